"""`arena run router`: a zenoh router for one match, started by hand (hardware in the loop,
`compose.yaml`); with `--credentials DIR` a secure one that provisions DIR once
(runtime/provision.py) and gives out one identity per process (match/claims.py)."""

from __future__ import annotations

import shutil
import signal
import sys
import time
from pathlib import Path

import zenoh

from arena.config import ConfigError
from arena.match.claims import Claims
from arena.runtime.credentials import COLLECTOR_PRINCIPAL, match_directory, secure_endpoint
from arena.runtime.mac import Keyring
from arena.runtime.provision import load, provision
from arena.runtime.session import NetConfig, open_session
from arena.schemas.keys import Keys, process_names


def _sigterm(signum, frame):
    raise SystemExit(128 + signum)


ROUTER_ROBOTS = 6  # a standalone router's credentials cover every robot a configuration may ask for


def secure_router(match: str, net: NetConfig, directory: str, private: Path) -> NetConfig:
    """A secure match's router (`arena run router --credentials DIR`): every principal's credentials
    file written into DIR, the router's passwords (a file in `private`, ours alone), access control
    and TLS certificate in its config."""
    if len(net.listen) != 1:
        raise ConfigError("arena run router --credentials needs one --listen endpoint")
    endpoint, _ = secure_endpoint(net.listen[0])
    names = [*process_names(ROUTER_ROBOTS), "refbox", COLLECTOR_PRINCIPAL]
    try:  # provisioned once: what DIR holds is kept (runtime/provision.py)
        creds, _ = provision(Path(directory), names, ROUTER_ROBOTS, match)
    except OSError as exc:
        raise ConfigError(f"cannot write --credentials {directory}: {exc.strerror}") from None
    return NetConfig(
        mode="router", listen=(endpoint,), connect=net.connect, extra=(*net.extra, *creds.router_settings(private))
    )


def run_router(match: str, net: NetConfig, credentials: str | None = None) -> int:
    """A zenoh router for one match; exits when every process of the match has left."""
    signal.signal(signal.SIGTERM, _sigterm)  # SystemExit: the password dictionary goes too
    private = match_directory("arena-router-")  # removed below, or by the next start if we are killed
    try:
        if not credentials:
            return _route(match, net, None)
        net = secure_router(match, net, credentials, private)
        held = load(Path(credentials))  # just provisioned: every principal's key, to check claims with
        return _route(match, net, held.keyring("launcher") if held is not None else None)
    finally:
        shutil.rmtree(private, ignore_errors=True)


def _route(match: str, net: NetConfig, keyring: Keyring | None) -> int:
    keys = Keys(match)
    alive: set[str] = set()
    seen = [False]

    def on_change(sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if sample.kind == zenoh.SampleKind.PUT:
            alive.add(key)
            seen[0] = True
        else:
            alive.discard(key)

    with open_session(NetConfig(mode="router", listen=net.listen, connect=net.connect, extra=net.extra)) as session:
        sub = session.liveliness().declare_subscriber(keys.alive_all(), on_change, history=True)
        said = lambda text: print(f"arena run: router: {text}", file=sys.stderr, flush=True)
        claims = Claims(session, keys, keyring, {}, said)  # one process per identity (match/claims.py)
        try:
            while not (seen[0] and not alive):
                time.sleep(0.2)
        finally:
            claims.close()
            sub.undeclare()
    return 0
