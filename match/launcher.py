"""`arena match`: one match as a group of OS processes, supervised.

The launcher hosts the match's zenoh router (a unix socket in a private temp
dir unless `--listen` says otherwise), starts every process with the same
job a user would start with `arena run <kind> ...` (match/run.py), waits
for each one's `Summary` (match/supervise.py), and assembles the match
result (match/result.py). Ctrl-C, or any child exiting with
an error, ends the whole group; children also die with the launcher
(PR_SET_PDEATHSIG), so no orphan survives.
"""

from __future__ import annotations

import compileall
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from arena.config import MatchConfig, ProcessId
from arena.match import forkstart
from arena.match.children import Child, MatchError, run_argv, spawn, stop_all, stopped_on_error
from arena.match.claims import Claims
from arena.match.joins import Joins, instructions
from arena.match.result import MatchResult, assemble, startup_seconds
from arena.match.run import run_job
from arena.match.supervise import Progress, open_collector, supervise, watch_spoofing
from arena.match.witness import Witness
from arena.runtime.acl import user_of
from arena.runtime.credentials import (
    OWNER,
    Secrets,
    drop_puts_towards,
    loopback_only,
    match_directory,
    new_zid,
    secure_endpoint,
)
from arena.runtime.provision import provision
from arena.runtime.session import EndpointError, NetConfig, check_endpoint, open_session
from arena.runtime.transport import ZenohTransport
from arena.runtime.version import PACKAGES
from arena.schemas.keys import OPERATOR_PRINCIPAL, Keys, routes

# Every package of the distribution; compiling one compiles its subpackages
# (arena.sim.physics, arena.strategies.iris, ...) too.
_PACKAGES = ("arena", *(f"arena.{p}" for p in PACKAGES))


def compile_sources() -> None:
    """Write the bytecode of arena's own modules before eleven interpreters import them.

    With PYTHONDONTWRITEBYTECODE set and an editable install (the README's),
    no interpreter writes a cache, so every process of every match compiled
    arena's sources again, about a second of CPU per match (docs/performance.md,
    "Measurements behind design choices"). This
    writes the usual `__pycache__` files of arena's own packages only (skipping
    fresh ones, a few ms), never anything else. Without the variable the
    interpreters write them themselves, so this does nothing.
    """
    if not sys.dont_write_bytecode:
        return
    for name in _PACKAGES:
        spec = importlib.util.find_spec(name)
        for root in (spec.submodule_search_locations or []) if spec else []:
            try:
                compileall.compile_dir(root, quiet=2)  # subpackages too: each root holds only arena's code
            except OSError:
                pass  # a read-only install: the processes compile in memory, as before


def new_match_id(seed: int) -> str:
    """Unique per run (isolation), never part of any digest."""
    return f"m{seed}-{os.getpid()}-{os.urandom(3).hex()}"


# The router of a peer match (not --secure) relays only to clients: spectators and
# hand-started processes; the lockstep runs on the peers' direct links. A put it
# relays is DROP on the way out: a slow spectator on `**` loses frames instead of
# blocking the router, which stopped reading from the peers, whose BLOCK puts then
# held their only zenoh thread until leases lapsed (tests/integration/test_spectator.py).
SPECTATOR_SAFE = (
    (
        "qos/network",
        json.dumps(
            [
                {
                    "id": "spectators",
                    "messages": ["put"],
                    "flows": ["egress"],
                    "overwrite": {"congestion_control": "drop"},
                }
            ]
        ),  # fmt: skip
    ),
)


def relay_safe(router_zid: str, peer: str, match: str, robots: int, external: set[str]) -> dict:
    """Zenoh settings of a peer this launcher starts in a peer match: what it puts towards the
    router is DROP, on its direct links to the other peers BLOCK as before.

    The router relays only to clients (spectators, hand-started processes), so nothing of the
    lockstep waits on it. Under BLOCK, a router behind on a peer's link filled that peer's
    queue towards it, and a put made in a zenoh callback (reactive nodes) then waited on
    zenoh's only thread, the one that would write the queue out: 5 s (`wait_before_close`),
    then the link closed and the router saw the peer's token vanish.

    Except for what an `--external` process (a client, through the router) receives: it
    waits for those frames in its lockstep, and a dropped one would stall it and blame it,
    so they stay BLOCK (the key table's receivers, and `referee`, which a process started
    by hand reads for the score). Then the rule names only the keys that may be dropped.
    """
    rule = drop_puts_towards("to-router", router_zid)
    if external:
        keys = Keys(match)
        table = routes(robots)
        kept = {rel for rel, _, receivers in table if external & set(receivers)} | {"referee"}
        dropped = [keys.prefix + rel for rel, sender, _ in table if sender == peer and rel not in kept]
        dropped += [keys.summary(peer), keys.tap(peer)]  # a summary is re-sent until acked
        rule[0]["key_exprs"] = dropped
    return {"qos": {"network": rule}}


def local_operator(cfg: MatchConfig, secure: bool, live_host: str, external) -> bool:
    """Whether the live viewer may sign Foxglove's `/operator` messages as the operator: it is
    started here (not `--external`), serves on a loopback address (whoever publishes there is on
    this computer) and the match is not `--secure` (where only the operator principal may put)."""
    local_viewer = cfg.live >= 0 and ProcessId("viewer") not in external
    return local_viewer and not secure and loopback_only(f"tcp/{live_host}:0")


def open_router(net: NetConfig, listen: str | None):
    """The match's router session; an endpoint that cannot be used is named as the user gave it."""
    try:
        return open_session(net)
    except EndpointError as exc:
        said = net.listen[0]
        if listen and said != listen:  # a secure match listens with TLS where --listen said tcp
            raise EndpointError(str(exc).replace(said, f"{listen} (as {said}: a secure match)", 1)) from None
        raise


def play_match(  # noqa: C901, PLR0912, PLR0915 - start, supervise and collect are one sequence
    cfg: MatchConfig,
    *,
    match: str | None = None,
    listen: str | None = None,
    progress: bool = False,
    log_dir: str | None = None,
    announce=None,
    strict: bool = False,
    live_host: str = "127.0.0.1",
    secure: bool | None = None,
    credentials: str | None = None,
    record: str = "",
) -> MatchResult:
    """Play one match as separate processes and return its result.

    `record`: an MCAP path; it reaches the recorder's argv only, the other
    processes see `cfg.tap`. `announce(text)` is called with instructions for
    `--external` processes.
    `secure`: authenticated principals, access control and TLS (runtime/acl.py,
    runtime/credentials.py); None means on whenever `listen` is not loopback.
    `credentials`: a credentials directory provisioned once (runtime/provision.py): what it
    holds is kept, what is missing made; the externals' files are named from it (default: a
    fresh set in the match's private temp dir, gone with it).
    A failed process is a fault in the result (`outcome`, `faults`: see
    match/faults.py); with `strict`, it raises MatchError instead, as does a
    match that cannot start.
    """
    if listen:  # a malformed endpoint is said before the match's processes are forked
        check_endpoint("--listen", listen)
    t_start = time.monotonic()
    launched = time.time()
    compile_sources()
    cfg = cfg.replace(tap=bool(record))
    match = match or new_match_id(cfg.seed)
    keys = Keys(match)
    secure = (not loopback_only(listen)) if secure is None else secure
    names = [str(p) for p in cfg.processes()]
    tls = secure and secure_endpoint(listen or "unixsock-stream/")[1]
    if credentials:  # provisioned once: what DIR holds is kept (runtime/provision.py)
        secrets, _ = provision(Path(credentials), names, cfg.robots, match)
        secrets.secure = secure
    else:
        secrets = Secrets.new(match, cfg.robots, names, secure, tls=tls)
    external = {ProcessId.parse(e) for e in cfg.external}
    local = [p for p in cfg.processes() if p not in external]
    tmp = match_directory()
    try:  # whatever fails from here on, the temp dir goes (the `finally` below covers the rest)
        endpoint = listen or f"unixsock-stream/{tmp}/router.sock"
        if secure:
            endpoint = secure_endpoint(endpoint)[0]
        connect = endpoint.replace("0.0.0.0", "127.0.0.1").replace("[::]", "[::1]")
        cfg_path = tmp / "config.json"
        cfg_path.write_text(cfg.to_json())
        logs = Path(log_dir) if log_dir else tmp
        logs.mkdir(parents=True, exist_ok=True)
        if secure:  # the viewer is served with DROP (Secrets.router_settings)
            more: dict[str, dict] = {}
            router_extra = tuple(secrets.router_settings(tmp))
        else:
            router_zid = new_zid()
            ext = {str(e) for e in external}
            more = {str(p): relay_safe(router_zid, str(p), match, cfg.robots, ext) for p in local}
            router_extra = (("id", json.dumps(router_zid)), *SPECTATOR_SAFE)
        # This match's own processes get theirs in the private temp dir (with this match's settings);
        # an external process's is in DIR, unchanged from match to match.
        # The live viewer forwards Foxglove's `/operator` messages signed as the operator only for a
        # local operator: a viewer this match starts, serving on a loopback address, not --secure.
        lend = {"viewer": (OPERATOR_PRINCIPAL,)} if local_operator(cfg, secure, live_host, external) else {}
        cred_paths = secrets.write(tmp / "credentials", more, launched={str(p) for p in local}, lend=lend)
        if credentials:
            cred_paths |= {str(p): Path(credentials) / f"{user_of(str(p))}.json5" for p in external}
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    children: list[Child] = []
    keep = False  # a failed match keeps its logs (and says where); anything else leaves nothing behind
    starter = None
    try:
        # Fork the processes before any zenoh session exists here (match/forkstart.py);
        # they open theirs once the router is up.
        starter = forkstart.starter(len(local), {p.kind for p in local}, {cfg.home, cfg.away})
        if starter is not None:
            for p in local:
                job = run_job(p, match, connect, str(cfg_path), record, live_host, str(cred_paths[str(p)]))
                log_path = logs / (str(p).replace("/", "_") + ".log")
                children.append(Child(str(p), p, starter.fork(job, log_path), log_path))  # type: ignore[arg-type]
        router_net = NetConfig(mode="router", listen=(endpoint,), extra=router_extra, lease=cfg.timing.lease)
        with open_router(router_net, listen) as session, stopped_on_error(children):
            transport = ZenohTransport(session, secrets.keyring("launcher"))
            collector = open_collector(transport, keys, names)
            watch_spoofing(transport, keys, announce)
            # An external's digest is recomputed from the frames it puts (match/witness.py).
            witness = Witness(transport, keys, cfg.robots, {str(p) for p in external}, cfg.timing.periods())
            # One identity, one process: arena match's own claim theirs by OS pid (match/claims.py).
            mine = f"started by arena match, pid {os.getpid()}"
            pid_of = lambda process: next((c.popen.pid for c in children if c.name == process), None)
            claims = Claims(session, keys, secrets.keyring("launcher"), {str(p): mine for p in local}, announce, pid_of)
            if starter is not None:
                starter.release()
            for p in cfg.processes() if starter is None else ():
                if p in external:
                    continue
                job = run_job(p, match, connect, str(cfg_path), record, live_host, str(cred_paths[str(p)]))
                children.append(spawn(str(p), p, run_argv(job), logs))
            if cfg.live >= 0 and announce is not None:
                pace = "" if cfg.realtime else f", pace {cfg.pace:g} (Foxglove parameters: paused, step, pace)"
                announce(f"live: connect the Foxglove app to ws://{live_host}:{cfg.live}{pace}")
            if (cfg.live >= 0 or cfg.realtime) and announce is not None:
                op = cred_paths[OPERATOR_PRINCIPAL]
                announce(f"operator: arena operator --match {match} --connect {connect} --credentials {op} ACTION")
            joins = Joins(session, keys, external, announce)
            if external and announce is not None:
                announce(instructions(sorted(external), match, endpoint, record, cred_paths, secure))
            try:
                joins.wait(cfg.timing.startup_timeout, children)
                if starter is not None:
                    starter.refill()  # a zygote forks the next match's children while this one plays
                got = supervise(
                    transport,
                    collector,
                    keys,
                    cfg,
                    children,
                    [str(p) for p in cfg.processes()],
                    Progress(cfg.total_ticks, progress),
                    strict=strict,
                    witness=witness,
                    announce=announce,
                )
            finally:
                joins.close()
                claims.close()
                transport.close()
        dead = {d for s in got.summaries.values() for d in s.dead} | set(got.lost) | set(got.missing)
        for c in children:
            if c.name in dead or got.void:
                continue  # hung, or a void match: stop_all below ends it
            try:
                c.popen.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        result = assemble(cfg, got, time.monotonic() - t_start, {c.name: c.popen.pid for c in children}, record)
        result.secure = secure
        result.refused_starts = claims.refused  # second starts of one identity, wrong credentials
        result.digests_verified = witness.verified()
        result.startup_seconds = startup_seconds(got.summaries, launched)
        result.launch = "exec" if starter is None else starter.how
        engine = got.summaries.get("engine")
        result.play_started_unix = engine.extra.get("play_started") if engine is not None else None
        if result.outcome != "completed" and log_dir is None:
            keep = True  # a fault's evidence
            result.logs = str(tmp)
        return result
    except MatchError as exc:
        if log_dir is None:
            keep = True
            raise type(exc)(f"{exc}\nevery process's log is kept in {tmp}") from None
        raise
    finally:
        if starter is not None:
            starter.close()  # children still waiting on the router read end-of-file and exit
        stop_all(children)
        if keep:  # the logs stay for the user to read; the secrets go now, and the owner mark
            for secret in (tmp / "credentials", tmp / "router-users.txt", tmp / OWNER):  # (`sweep` keeps it)
                shutil.rmtree(secret, ignore_errors=True) if secret.is_dir() else secret.unlink(missing_ok=True)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
