"""`arena run <kind>`: start one process of a match on its own.

This is the hardware-in-the-loop path: the same command runs a robot's
process on the robot's own computer, or a base station on the team's laptop,
against the rest of the match.

Where the match configuration comes from:
* `--config FILE` (what `arena match` passes to its children), or
* for the engine, its own flags (`--home`, `--away`, `--robots`, ...), or
* for everyone else, the engine's `arena/<m>/config` queryable, asked until the
  startup timeout.
"""

from __future__ import annotations

import logging
import signal
import sys
import time
from pathlib import Path

import zenoh

from arena.processes import node_class
from arena.runtime.config import ConfigError, MatchConfig, ProcessId
from arena.runtime.node import StartupError
from arena.runtime.session import NetConfig, open_session
from arena.runtime.transport import ZenohTransport
from arena.schemas.keys import Keys


def _sigterm(signum, frame):  # noqa: ARG001 - signal handler signature
    raise SystemExit(128 + signum)


def process_id(kind: str, team: str | None, robot: int | None) -> ProcessId:
    if kind in ("robot", "basestation") and team is None:
        raise ConfigError(f"arena run {kind} needs --team a|b")
    if kind == "robot" and robot is None:
        raise ConfigError("arena run robot needs --robot N")
    if kind not in ("robot", "basestation") and (team is not None or robot is not None):
        raise ConfigError(f"--team/--robot do not apply to {kind}")
    if kind == "basestation" and robot is not None:
        raise ConfigError("--robot does not apply to basestation")
    if kind == "robot":
        return ProcessId("robot", team or "", int(robot or 0))
    if kind == "basestation":
        return ProcessId("basestation", team or "")
    return ProcessId(kind)


def load_config(path: str) -> MatchConfig:
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise ConfigError(f"cannot read --config {path}: {exc.strerror}") from None
    return MatchConfig.from_json(text)


def fetch_config(transport: ZenohTransport, keys: Keys, timeout: float) -> MatchConfig:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        payload = transport.query(keys.config(), timeout=1.0)
        if payload is not None:
            return MatchConfig.from_json(payload.decode())
        time.sleep(0.2)
    raise StartupError(
        f"no match configuration on {keys.config()} after {timeout:g} s: is the engine of match "
        f"{keys.match!r} running and reachable on the given endpoint?"
    )


def run(
    pid: ProcessId,
    match: str,
    net: NetConfig,
    cfg: MatchConfig | None,
    seed: int | None,
    realtime: bool,
    startup_timeout: float,
    record: str | None = None,
) -> int:
    """Run one process to the end of its match. Returns the exit code.

    `record`: the recorder's output path; it overrides the configuration's
    (which names the path on the machine that started the match).
    """
    signal.signal(signal.SIGTERM, _sigterm)
    keys = Keys(match)
    log = logging.getLogger(f"arena.{pid}")
    with open_session(net) as session:
        transport = ZenohTransport(session)
        try:
            if cfg is None:
                cfg = fetch_config(transport, keys, startup_timeout)
            if seed is not None and seed != cfg.seed:
                raise ConfigError(f"--seed {seed} differs from the match's seed {cfg.seed}")
            if realtime and not cfg.realtime:
                raise ConfigError("--realtime given, but the match runs in lockstep")
            if pid.kind == "recorder":
                if not cfg.record:
                    raise ConfigError(f"match {match!r} does not record: start it with --record FILE.mcap")
                if record:
                    cfg = cfg.replace(record=record)
            if pid not in cfg.processes():
                raise ConfigError(f"{pid} is not part of this match ({cfg.robots} robots per team)")
            node = node_class(pid.kind)(pid, cfg, transport, keys)
            node.run()
        finally:
            transport.close()
    log.debug("%s done", pid)
    return 0


def run_router(match: str, net: NetConfig) -> int:
    """A zenoh router for one match; exits when every process of the match has left."""
    signal.signal(signal.SIGTERM, _sigterm)
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
        try:
            while not (seen[0] and not alive):
                time.sleep(0.2)
        finally:
            sub.undeclare()
    return 0


def main_guarded(fn, *args) -> int:
    """Turn the expected failures into one-line messages and exit codes."""
    try:
        return fn(*args)
    except ConfigError as exc:
        print(f"arena run: error: {exc}", file=sys.stderr)
        return 2
    except StartupError as exc:
        print(f"arena run: error: {exc}", file=sys.stderr)
        return 3
    except zenoh.ZError as exc:
        print(f"arena run: zenoh error: {exc}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print("arena run: interrupted", file=sys.stderr)
        return 130
