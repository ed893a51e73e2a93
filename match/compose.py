"""`arena up compose.yaml`: the compose file's services as local processes.

No Docker engine runs on our machines, so this reads the very same file
`docker compose up` would, expands its `${VAR:-default}` variables, and starts
each service's `command` as a local process, the router first. It sets
`ARENA_MATCH` to a fresh match id and `ARENA_LISTEN`/`ARENA_CONNECT` to a unix
socket in a private temp dir, so that a local run is isolated like any match;
an `ARENA_MATCH` set in the environment is kept (a known key prefix for a
viewer or a recorder started by hand).
Then it supervises the services and prints the match result like `arena match`.
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import sys
import time
from pathlib import Path

import yaml

from arena.config import ConfigError, MatchConfig, ProcessId
from arena.match import launcher
from arena.match.children import Child, MatchError, spawn, stop_all
from arena.match.result import MatchResult, assemble
from arena.match.run import load_credentials
from arena.match.supervise import Progress, open_collector, supervise
from arena.runtime.credentials import COLLECTOR_PRINCIPAL, OWNER, match_directory
from arena.runtime.session import NetConfig, open_session
from arena.runtime.transport import ZenohTransport
from arena.schemas.keys import Keys, check_match_id, process_names

MAX_ROBOTS = 6  # robots per team a configuration may ask for (config/__init__.py)

_VAR = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)(?::?-([^}]*))?\}")


class ComposeError(RuntimeError):
    def __init__(self, message: str, bad_input: bool = False):
        super().__init__(message)
        self.bad_input = bad_input


def expand(text: str, env: dict[str, str]) -> str:
    return _VAR.sub(lambda m: env.get(m.group(1)) or (m.group(2) or ""), text)


def load_services(path: str, env: dict[str, str]) -> dict[str, list[str]]:
    """service name -> argv, in start order (services others depend on first)."""
    from arena.runtime import userfile

    try:
        raw = userfile.read_text(path, "compose file")  # regular, bounded, UTF-8
    except ConfigError as exc:
        raise ComposeError(str(exc), bad_input=True) from None
    try:
        doc = yaml.safe_load(expand(raw, env))
    except yaml.YAMLError as exc:
        raise ComposeError(f"{path} is not valid YAML: {str(exc).splitlines()[0]}", bad_input=True) from None
    except RecursionError:  # the YAML composer recurses per level of nesting
        raise ComposeError(f"{path} nests too deep to read", bad_input=True) from None
    services = (doc or {}).get("services") if isinstance(doc, dict) else None
    if not isinstance(services, dict) or not services:
        raise ComposeError(f"{path} has no services", bad_input=True)
    commands: dict[str, list[str]] = {}
    deps: dict[str, list[str]] = {}
    for name, svc in services.items():
        cmd = (svc or {}).get("command")
        if isinstance(cmd, str):
            cmd = cmd.split()
        if not isinstance(cmd, list) or not cmd or cmd[0] != "arena":
            raise ComposeError(f"service {name!r}: command must be an 'arena ...' list", bad_input=True)
        commands[name] = [str(c) for c in cmd]
        d = (svc or {}).get("depends_on") or []
        deps[name] = list(d) if isinstance(d, (list, dict)) else []
    order: list[str] = []

    def visit(n: str, stack: tuple[str, ...] = ()) -> None:
        if n in order:
            return
        if n in stack:
            raise ComposeError(f"dependency cycle at service {n!r}", bad_input=True)
        for d in deps.get(n, []):
            if d not in commands:
                raise ComposeError(f"service {n!r} depends on unknown service {d!r}", bad_input=True)
            visit(d, (*stack, n))
        order.append(n)

    for n in commands:
        visit(n)
    return {n: commands[n] for n in order}


def _process_of(argv: list[str]) -> ProcessId | None:
    """The ProcessId an `arena run <kind> ...` command line starts (None for the router)."""
    kind = argv[2] if len(argv) > 2 and argv[1] == "run" else ""
    if kind == "router":
        return None
    team = argv[argv.index("--team") + 1] if "--team" in argv else ""
    robot = int(argv[argv.index("--robot") + 1]) if "--robot" in argv else -1
    if kind == "robot":
        return ProcessId("robot", team, robot)
    if kind == "basestation":
        return ProcessId("basestation", team)
    return ProcessId(kind)


def up(path: str, timeout: float = 600.0) -> MatchResult:
    t_start = time.monotonic()
    match = os.environ.get("ARENA_MATCH") or launcher.new_match_id(0)
    try:
        check_match_id(match)
    except ValueError as exc:
        raise ComposeError(f"ARENA_MATCH: {exc}", bad_input=True) from None
    tmp = match_directory("arena-up-")  # private; swept by the next start if we are killed
    sock = tmp / "router.sock"
    env = dict(os.environ)
    env.update(
        ARENA_MATCH=match,
        ARENA_LISTEN=f"unixsock-stream/{sock}",
        ARENA_CONNECT=f"unixsock-stream/{sock}",
        ARENA_CREDENTIALS=str(tmp / "credentials"),
    )
    children: list[Child] = []
    keep = False  # a failed match keeps the services' logs (and says where); bad input leaves nothing behind
    try:
        services = load_services(path, env)
        routers = [n for n, argv in services.items() if _process_of(argv) is None]
        if len(routers) != 1:
            raise ComposeError(f"{path} must have exactly one router service ('arena run router ...')", bad_input=True)
        router = routers[0]
        _same_match(services, router)
        children.append(spawn(router, ProcessId("router"), _argv(services[router]), tmp, env=env))
        _wait_for_socket(sock, children[0])
        net, keyring = _collector_net(env, router_argv=services[router], match=match)
        with open_session(net) as session:
            transport = ZenohTransport(session, keyring)
            keys = Keys(match)
            # The configuration (how many robots) comes from the engine later: listen for any.
            collector = open_collector(transport, keys, process_names(MAX_ROBOTS))
            for name, argv in services.items():
                if name != router:
                    children.append(spawn(name, _process_of(argv), _argv(argv), tmp, env=env))
            cfg = _fetch(transport, keys, children)
            print(
                f"arena up: {cfg.home} (a) vs {cfg.away} (b), 2 x {cfg.half_time:g} s simulated, seed {cfg.seed}, "
                f"link {cfg.link} (the environment's ARENA_HOME, ARENA_AWAY, ARENA_HALF_TIME, ARENA_SEED and "
                "ARENA_LINK change them)",
                file=sys.stderr,
            )
            declared = {c.pid for c in children if c.name != "router"}
            missing = [str(p) for p in cfg.processes() if p not in declared]
            if missing:
                raise ComposeError(
                    f"{path} has no service for: {', '.join(missing)} (arena up plays every process itself; for "
                    "hardware in the loop use arena match --external, or docker compose)",
                    bad_input=True,
                )
            named = [c for c in children if c.pid.kind != "router"]
            for c in named:
                c.name = str(c.pid)
            try:
                got = supervise(
                    transport,
                    collector,
                    keys,
                    cfg,
                    named,
                    [str(p) for p in cfg.processes()],
                    Progress(cfg.total_ticks, False),
                    timeout=timeout,
                )
            except MatchError as exc:
                raise ComposeError(str(exc)) from None
            finally:
                transport.close()
        result = assemble(cfg, got, time.monotonic() - t_start, {c.name: c.popen.pid for c in children})
        result.services = list(services)
        result.secure = "--credentials" in services[router]
        return result
    except ComposeError as exc:
        if exc.bad_input:
            raise
        keep = True
        raise ComposeError(f"{exc}\nevery service's log is kept in {tmp}") from None
    finally:
        stop_all(children)
        if keep:  # the logs stay, the credentials the router service wrote go (and the owner mark)
            shutil.rmtree(tmp / "credentials", ignore_errors=True)
            (tmp / OWNER).unlink(missing_ok=True)
        else:
            shutil.rmtree(tmp, ignore_errors=True)


def _collector_net(env: dict[str, str], router_argv: list[str], match: str):
    """How `arena up` joins as the summary collector: with the `collector` credentials when the
    router service makes the match secure (`--credentials DIR`), else as a plain client."""
    net = NetConfig(mode="client", connect=(env["ARENA_CONNECT"],))
    if "--credentials" not in router_argv:
        return net, None
    path = str(Path(router_argv[router_argv.index("--credentials") + 1]) / f"{COLLECTOR_PRINCIPAL}.json5")
    try:
        base, _, keyring = load_credentials(path, COLLECTOR_PRINCIPAL, wait=30.0)
    except ConfigError as exc:
        raise ComposeError(f"the router service's credentials: {exc}") from None
    return dataclasses.replace(net, base=base), keyring


def _same_match(services: dict[str, list[str]], router: str) -> None:
    """ComposeError (bad input) when a service names another match than the router's: it would wait
    for a match that never starts, and the match for it."""

    def match_of(argv: list[str]) -> str | None:
        return argv[argv.index("--match") + 1] if "--match" in argv[:-1] else None

    want = match_of(services[router])
    for name, argv in services.items():
        got = match_of(argv)
        if got is not None and want is not None and got != want:
            raise ComposeError(
                f"service {name!r}: --match {got!r} is not the router's match {want!r} (a typo?)", bad_input=True
            )


def _exited(c: Child) -> ComposeError:
    """A service that ended before the match started: its exit code 2 means it refused its command
    line or environment (one line: the last of its log), which is bad input, as for arena run."""
    if c.popen.returncode == 2:
        last = (c.tail(1).strip() or "no output").removeprefix("arena run: error: ")
        return ComposeError(f"service {c.name} refused to start: {last}", bad_input=True)
    return ComposeError(f"service {c.name} exited with code {c.popen.returncode}:\n{c.tail()}")


def _argv(argv: list[str]) -> list[str]:
    """`arena ...` from the compose file, run with this very Python."""
    return [sys.executable, "-m", "arena", *argv[1:]]


def _wait_for_socket(sock: Path, router: Child, limit: float = 30.0) -> None:
    deadline = time.monotonic() + limit
    while not sock.exists():
        if router.popen.poll() is not None:
            raise _exited(router)
        if time.monotonic() > deadline:
            raise ComposeError("the router service did not start listening")
        time.sleep(0.05)


def _fetch(transport: ZenohTransport, keys: Keys, children: list[Child]) -> MatchConfig:
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        for c in children:
            if c.popen.poll() not in (None, 0):
                raise _exited(c)
        ring = transport.keyring  # with the collector's credentials: only the engine's answer (its MAC)
        verify = ring.verifier("engine", keys.config()) if ring is not None else None
        payload = transport.query(keys.config(), timeout=1.0, verify=verify)
        if payload is not None:
            try:
                return MatchConfig.from_json(payload.decode())
            except ConfigError as exc:
                raise ComposeError(str(exc)) from None
        time.sleep(0.1)
    raise ComposeError("no engine answered with the match configuration within 60 s")
