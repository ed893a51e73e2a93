"""`arena run <kind>`: start one process of a match on its own.

This is the hardware-in-the-loop path: the same command runs a robot's
process on the robot's own computer, or a base station on the team's laptop,
against the rest of the match.

Where the match configuration comes from:
* `--config FILE` (what `arena match` passes to its children), or
* for the engine, its own flags (`--home`, `--away`, `--robots`, ...), or
* for everyone else, the engine's `arena/<m>/config` queryable, asked until the
  startup timeout. Only an answer with the engine's MAC counts (the key is in
  the process's credentials file, `--credentials`); the others are counted as
  forged on `config` and warned about. Without credentials a process can
  verify nothing: it takes the first answer (docs/architecture.md, "Trust").
"""

from __future__ import annotations

import dataclasses
import faulthandler
import json
import logging
import signal
import sys
import time
from pathlib import Path

import msgspec
import zenoh

from arena.config import ConfigError, MatchConfig, ProcessId
from arena.match.claims import hold_identity
from arena.match.connect import why_refused
from arena.processes import OBSERVERS, node_class
from arena.runtime.acl import user_of
from arena.runtime.credentials import load_fragment
from arena.runtime.drivers import Driver, Pull, WaitBoard
from arena.runtime.mac import Keyring
from arena.runtime.node import StartupError
from arena.runtime.session import EndpointError, NetConfig, check_endpoint, listening, open_session
from arena.runtime.transport import ZenohTransport
from arena.schemas.keys import Keys, check_match_id
from arena.schemas.messages import Referee


class Job(msgspec.Struct, frozen=True, omit_defaults=True):
    """One process of a match to start: what `arena run` parses its flags into, and what a
    forked or zygote child of `arena match` gets from the launcher, typed (no argv to parse).

    A field left at None means the flag was not given (`argv` leaves it out)."""

    kind: str  # a process kind, or "router"
    match: str
    connect: tuple[str, ...] = ()
    listen: tuple[str, ...] = ()
    mode: str | None = None  # zenoh mode: peer (default) | client
    team: str | None = None
    robot: int | None = None
    seed: int | None = None
    realtime: bool = False
    config: str | None = None  # the match configuration JSON written by `arena match`
    policy: str | None = None  # this computer's copy of the team's policy file
    credentials: str | None = None
    startup_timeout: float | None = None
    log_level: str | None = None
    record: str | None = None
    host: str | None = None
    port: int | None = None

    def argv(self) -> list[str]:
        """The same job as an `arena` command line: `run <kind> --match ...` (exec'd children, hand-started ones)."""
        out = ["run", self.kind, "--match", self.match]
        out += [x for ep in self.connect for x in ("--connect", ep)]
        out += [x for ep in self.listen for x in ("--listen", ep)]
        for flag, value in (
            ("--credentials", self.credentials),
            ("--team", self.team),
            ("--robot", self.robot),
            ("--record", self.record),
            ("--host", self.host),
            ("--config", self.config),
            ("--policy", self.policy),
            ("--seed", self.seed),
            ("--mode", self.mode),
            ("--startup-timeout", self.startup_timeout),
            ("--log-level", self.log_level),
            ("--port", self.port),
        ):
            if value is not None:
                out += [flag, str(value)]
        return out + (["--realtime"] if self.realtime else [])


def run_job(
    pid: ProcessId,
    match: str,
    connect: str,
    config_path: str | None = None,
    record: str = "",
    host: str = "",
    credentials: str | None = None,
) -> Job:
    """The job of one of the match's processes (forked, or exec'd as `arena run ...`)."""
    return Job(
        kind=pid.kind,
        match=match,
        connect=(connect,),
        credentials=credentials or None,
        team=pid.team or None,
        robot=pid.robot if pid.kind == "robot" else None,
        record=record if pid.kind == "recorder" and record else None,
        host=host if pid.kind == "viewer" and host else None,
        config=config_path or None,
    )


def start(job: Job, cfg: MatchConfig | None = None) -> int:
    """Run the process `job` names to the end of its match; the exit code (2 for bad input, one line).

    `cfg`: the match an engine hosts when `job.config` names no file (`arena run engine --home ...`)."""
    configure_logging(job.log_level or "WARNING", by_hand=job.config is None)
    net = NetConfig(mode=job.mode or "peer", connect=job.connect, listen=job.listen)
    if job.kind == "router":
        from arena.match.router import run_router

        return main_guarded(run_router, job.match, net, job.credentials)
    keyring = None
    try:
        pid = process_id(job.kind, job.team, job.robot)
        if job.credentials:
            base, mode, keyring = load_credentials(job.credentials, pid, wait=10.0)
            net = dataclasses.replace(net, base=base, mode=mode or net.mode)
        if job.config:
            cfg = load_config(job.config)
        if job.record and job.kind not in ("engine", "recorder"):
            raise ConfigError(f"--record does not apply to {job.kind}")
        policy = None
        if job.policy:
            if job.kind not in ("robot", "basestation"):
                raise ConfigError(f"--policy applies to a robot or a base station, not to {job.kind}")
            from arena.strategies import registry

            policy = registry.resolve_name(f"policy:{job.policy}")
        if job.port is not None and (job.kind != "viewer" or not 0 <= job.port <= 65535):
            raise ConfigError("--port applies to the viewer only, 0..65535")
        record = record_path(job.record) if job.record and job.kind == "recorder" else None
        check_match_id(job.match)
    except (ConfigError, ValueError) as exc:
        print(f"arena run: error: {exc}", file=sys.stderr)
        return 2
    if cfg is not None:  # known before the session opens: its lease is the match's
        net = dataclasses.replace(net, lease=cfg.timing.lease)
    timeout = job.startup_timeout if job.startup_timeout is not None else 60.0
    host = job.host or "127.0.0.1"
    return main_guarded(
        run,
        pid,
        job.match,
        net,
        cfg,
        job.seed,
        job.realtime,
        timeout,
        record,
        host,
        job.port,
        keyring,
        policy,
        job.credentials,
    )


def _sigterm(signum, frame):
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


def load_credentials(path: str, pid: ProcessId | str, wait: float = 0.0) -> tuple[str, str | None, Keyring]:
    """(fragment JSON, zenoh mode it asks for, keyring) from `--credentials FILE`, checked against who we are.

    The file is not tied to a match: one provisioned once (`--credentials DIR`) serves every match
    that uses its directory. `wait`: the file may not be there yet (a router service writes it as
    it starts): wait this long."""
    deadline = time.monotonic() + wait
    # A directory that is still there may be about to get it (a router service); a gone one will not.
    near = Path(path).parent.is_dir() or Path(path).parent.parent.is_dir()
    while not Path(path).exists() and near and time.monotonic() < deadline:
        time.sleep(0.1)
    if not Path(path).exists():
        raise ConfigError(
            f"cannot read --credentials {path}: no such file (a match's temp dir is gone with its match: "
            "provision once with arena match --credentials DIR, or arena credentials init DIR)"
        )
    try:
        frag = load_fragment(path)
        arena = frag["metadata"]["arena"]
        keyring = Keyring.from_hex(arena["process"], arena.get("keys", {}))
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    if arena["process"] != str(pid):
        raise ConfigError(f"--credentials {path} is {arena['process']}'s, not {pid}'s: give {user_of(str(pid))}.json5")
    mode = frag.get("mode")
    return json.dumps(frag), mode if mode in ("peer", "client") else None, keyring


class _Said(logging.Formatter):
    """A log record as one of `arena run`'s own lines: `arena run: robot/a/1: warning: ...`."""

    def format(self, record: logging.LogRecord) -> str:
        text = f"arena run: {record.name.removeprefix('arena.')}: {record.levelname.lower()}: {record.getMessage()}"
        return text + ("\n" + self.formatException(record.exc_info) if record.exc_info else "")


def configure_logging(level: str, by_hand: bool, stream=None) -> None:
    """stderr logging: a process started by hand (no --config) says its lines as `arena run` says
    everything else; one started by `arena match` writes its log file with times."""
    handler = logging.StreamHandler(stream or sys.stderr)
    fmt = "%(asctime)s %(name)s %(levelname)s %(message)s"
    handler.setFormatter(_Said() if by_hand else logging.Formatter(fmt))
    logging.basicConfig(level=level, handlers=[handler], force=True)


def load_config(path: str) -> MatchConfig:
    """The match configuration JSON at `path` (regular, bounded, UTF-8: runtime/userfile.py)."""
    from arena.runtime import userfile

    return MatchConfig.from_json(userfile.read_text(path, "--config"))


def record_path(text: str, fresh: bool = False) -> str:
    """An absolute path for a new MCAP file whose directory exists (children may run elsewhere).

    `fresh`: an existing file is refused, not overwritten (arena match; the recorder
    it starts gets the path it checked)."""
    path = Path(text).expanduser().resolve()
    if not path.parent.is_dir():
        raise ConfigError(f"--record {text}: directory {path.parent} does not exist")
    if path.is_dir():
        raise ConfigError(f"--record {text} is a directory")
    if fresh and path.exists():
        size = path.stat().st_size / 1e6
        raise ConfigError(f"--record {text} exists ({size:.1f} MB): give a new file name, or delete it first")
    # Tried now, not by the recorder after the match has started: a recorder that
    # cannot write holds every process at the start barrier until it times out.
    existed = path.exists()
    try:
        with open(path, "ab"):
            pass
    except OSError as exc:
        raise ConfigError(f"--record {text}: cannot write it ({exc.strerror or exc})") from None
    if not existed:
        path.unlink()
    return str(path)


REFUSED_AFTER = 6.0  # [s] listening but not connected this long is a refusal: zenoh retries a connect every <= 4 s
ROUTER_RETRY_S = 0.25  # [s] wall: pause between attempts to reach a router that is not there yet
REFUSED_TWICE_S = 1.0  # [s] wall: a router refusing us this long after its first refusal is not one still starting
CONFIG_GRACE_S = 1.0  # [s] wall: connected this long without the match's configuration, the match is not there yet


def refused_by(connect: tuple[str, ...]) -> str | None:
    """The endpoint of `connect` at which something listens (a router that did not have us), if any."""
    return next((ep for ep in connect if listening(ep)), None)


def refusal(ep: str, net: NetConfig, credentials: str | None, pid: str) -> ConfigError:
    """The refusal of the router at `ep`, with its cause (match/connect.py)."""
    fragment = json.loads(net.base) if net.base else None
    return ConfigError(why_refused(ep, fragment, credentials, user_of(pid)))


def without_password(net: NetConfig) -> NetConfig | None:
    """`net` without the user and password of its credentials (None if it has none): a file
    provisioned once is a secure match's, and a plain match's router refuses a password."""
    fragment = json.loads(net.base) if net.base else {}
    auth = fragment.get("transport", {}).get("auth")
    if not auth or any(ep.startswith(("tls/", "quic/")) for ep in net.connect):
        return None
    del fragment["transport"]["auth"]
    return dataclasses.replace(net, base=json.dumps(fragment))


def fetch_config(
    transport: ZenohTransport,
    keys: Keys,
    timeout: float,
    session=None,
    where: str = "",
    tell=None,
    connect: tuple[str, ...] = (),
    refused=None,
    forged: list[int] | None = None,
) -> MatchConfig:
    """Ask the engine for the match configuration until `timeout`; say what we wait for (`tell`).

    With the engine's key (`transport.keyring`), only its answer counts: every other one is
    counted in `forged` (`forged[0]`, before the process's node exists) and warned about once."""
    deadline = time.monotonic() + timeout
    state = said = ""  # what we wait for now, and what we last told
    ring = transport.keyring
    verify = ring.verifier("engine", keys.config()) if ring is not None else None
    node_warns = forged is not None  # the caller's node warns (`Rejections.forged`)
    forged = [0] if forged is None else forged

    def on_forged() -> None:
        forged[0] += 1
        if not node_warns and forged[0] == 1:
            logging.getLogger("arena.config").warning("possible spoofing on %s", keys.config())

    ep = None
    elsewhere = ""  # the other matches the router we reached hosts
    refused_since: float | None = None  # a router listens, and we are still not connected to it
    connected_since: float | None = None  # a fresh connection learns the engine's queryable a moment later
    while time.monotonic() < deadline:
        payload = transport.query(keys.config(), timeout=1.0, verify=verify, on_forged=on_forged)
        if payload is not None:
            return MatchConfig.from_json(payload.decode())
        if session is not None:
            connected = bool(list(session.info.routers_zid()) or list(session.info.peers_zid()))
            probe = None if connected else refused_by(connect)
            if connected:
                refused_since = None
                connected_since = connected_since or time.monotonic()
            elif probe is not None:  # (a probe that fails on a loaded host proves nothing)
                ep = probe
                refused_since = refused_since or time.monotonic()
                if time.monotonic() - refused_since > REFUSED_AFTER:
                    raise refused(ep) if refused is not None else ConfigError(f"refused by {ep}")
            # A router that listens and has not taken us yet is told apart within REFUSED_AFTER.
            now = f"waiting for match {keys.match!r} to start at {where}" if connected else f"no router at {where}"
            if connected:  # a typo in --match is said with the match that is there
                elsewhere = elsewhere or hosted_elsewhere(session, keys)
                now += elsewhere
            # Connected, a match that is there answers within CONFIG_GRACE_S: only then is it "waiting".
            settled = not connected or time.monotonic() - (connected_since or 0.0) >= CONFIG_GRACE_S
            if now != said and tell is not None and settled and (connected or refused_since is None):
                tell(f"{now if connected else 'waiting: ' + now} (up to {timeout:g} s)")
                said = now
            state = now
        time.sleep(0.2)
    if refused_since is not None and refused is not None and ep is not None:
        raise refused(ep)  # a router listens there and never took us: say why, not "no router"
    ignored = (
        f"; ignored {forged[0]} answer(s) without the engine's MAC (possible spoofing, or an engine "
        "started without its --credentials)"
        if forged[0]
        else ""
    )
    raise StartupError(
        (
            f"gave up after {timeout:g} s{' ' if state.startswith('waiting') else ': '}{state}"
            if state
            else f"no match configuration on {keys.config()} after {timeout:g} s: is the engine of match "
            f"{keys.match!r} running and reachable on the given endpoint?"
        )
        + ignored
    )


def hosted_elsewhere(session, keys: Keys) -> str:
    """`; the router hosts match 'x'` when the router we reached plays other matches than ours."""
    others = set()
    for reply in session.liveliness().get("arena/*/alive/engine", timeout=0.5):
        if reply.ok is not None:
            others.add(str(reply.ok.key_expr).split("/")[1])
    others.discard(keys.match)
    return f"; the router hosts match {', '.join(repr(m) for m in sorted(others))}" if others else ""


def open_until(net: NetConfig, timeout: float, where: str, tell, refused):
    """Open the session; a client retries until `timeout` while no router answers at its endpoint.

    A router that listens and refuses us twice, REFUSED_TWICE_S apart (not one still starting),
    is a refusal with its cause (`refused(ep)`), unless it takes us without the password of a
    credentials file provisioned once (a plain match's router). Attempts are ROUTER_RETRY_S
    apart, so a process started before its router connects within that of the router's start."""
    for ep in net.connect:
        check_endpoint("--connect", ep)
    deadline = time.monotonic() + timeout
    told = False
    refused_since: float | None = None  # the first refusal of this run of refusals
    while True:
        try:
            return open_session(net)
        except EndpointError:
            if net.mode != "client" or not net.connect:
                raise
            ep = refused_by(net.connect)
            if ep is not None:
                plain = without_password(net)
                if plain is not None:
                    try:
                        session = open_session(plain)
                    except EndpointError:
                        pass
                    else:
                        tell(f"{ep} is not a secure match's router: connected without the password")
                        return session
                now = time.monotonic()
                if refused_since is not None and now - refused_since >= REFUSED_TWICE_S:
                    raise refused(ep) from None  # refused all along: not a router still starting
                refused_since = refused_since if refused_since is not None else now
            else:
                refused_since = None
            if time.monotonic() + ROUTER_RETRY_S > deadline:
                raise StartupError(f"gave up after {timeout:g} s: no router at {where}") from None
            if not told and ep is None:
                tell(f"waiting: no router at {where} (retrying for up to {timeout:g} s)")
                told = True
            time.sleep(ROUTER_RETRY_S)


def with_policy(cfg: MatchConfig, team: str, policy: str) -> MatchConfig:
    """`cfg` with team `team`'s policy file replaced by `policy` (`policy:PATH`, this computer's copy)."""
    if not cfg.strategy_of(team).startswith("policy:"):
        raise ConfigError(f"--policy: team {team} plays {cfg.strategy_of(team)}, not a policy file")
    return cfg.replace(**{"home" if team == "a" else "away": policy})


def driver(pid: ProcessId, cfg: MatchConfig, transport: ZenohTransport, keys: Keys) -> dict[str, Driver]:
    """The driver of a lockstep node over zenoh, as a keyword for its constructor (none for an observer):
    the receive callbacks (`Reactor`, blaming silent peers by their announced waits), or in real time
    a blocking `Pull`."""
    if pid.kind in OBSERVERS:
        return {}
    timeout = cfg.timing.wait_timeout
    if cfg.realtime:
        return {"driver": Pull(transport, timeout)}
    return {"driver": WaitBoard(transport, keys, str(pid)).reactor(timeout)}


def run(
    pid: ProcessId,
    match: str,
    net: NetConfig,
    cfg: MatchConfig | None,
    seed: int | None,
    realtime: bool,
    startup_timeout: float,
    record: str | None = None,
    host: str = "127.0.0.1",
    port: int | None = None,
    keyring: Keyring | None = None,
    policy: str | None = None,
    credentials: str | None = None,
) -> int:
    """Run one process to the end of its match. Returns the exit code.

    `policy`: a robot's or base station's own copy of the policy file its team plays, as the
    strategy name `policy:PATH` (the match's names a path on the computer that started it).

    `record`: the recorder's output path; it overrides the configuration's
    (which names the path on the machine that started the match).

    Started by hand (no `--config`: the robot on its own computer), it says on
    stderr what it connected to, whom it waits for, and the final score.
    """
    signal.signal(signal.SIGTERM, _sigterm)
    # `kill -USR1 PID` writes every thread's Python stack to this process's log: what a hung match waits in.
    faulthandler.register(signal.SIGUSR1, all_threads=True)
    keys = Keys(match)
    log = logging.getLogger(f"arena.{pid}")
    talk = cfg is None or sys.stderr.isatty()

    def tell(text: str) -> None:
        if talk:
            print(f"arena run: {pid}: {text}", file=sys.stderr, flush=True)

    where = ", ".join(net.connect or net.listen)
    last_ref: list[bytes] = []

    def refused(ep: str) -> ConfigError:
        return refusal(ep, net, credentials, str(pid))

    with open_until(net, startup_timeout, where, tell, refused) as session:
        transport = ZenohTransport(session, keyring)
        ref_sub = None
        forged = [0]  # answers to our `config` query without the engine's MAC
        try:
            if cfg is None:
                cfg = fetch_config(transport, keys, startup_timeout, session, where, tell, net.connect, refused, forged)
            if seed is not None and seed != cfg.seed:
                raise ConfigError(f"--seed {seed} differs from the match's seed {cfg.seed}")
            if realtime and not cfg.realtime:
                raise ConfigError("--realtime given, but the match runs in lockstep")
            cfg, extra = observer_settings(pid, cfg, match, record, host, port)
            if pid not in cfg.processes():
                raise ConfigError(f"{pid} is not part of this match ({cfg.robots} robots per team)")
            if policy:
                cfg = with_policy(cfg, pid.team, policy)
            held = hold_identity(session, keys, pid, keyring)  # noqa: F841 - kept while it runs
            tell(
                f"connected to {where} (zenoh {net.mode}); match {match!r}: {cfg.home} v {cfg.away}, "
                f"{cfg.robots} robots per team, 2 x {cfg.half_time:g} s"
            )
            if talk:
                ref_sub = session.declare_subscriber(
                    keys.key("referee"), lambda s: last_ref[:1].clear() or last_ref.append(s.payload.to_bytes())
                )
            node = node_class(pid.kind)(pid, cfg, transport, keys, **extra, **driver(pid, cfg, transport, keys))
            for _ in range(forged[0]):  # counted in its summary as every forged frame is (runtime/lockstep.py)
                node.rejections.forged(keys.config(), "engine")
            node.on_waiting = lambda missing: tell(
                f"waiting for: {', '.join(missing)} (up to {cfg.timing.startup_timeout:g} s)"
                if missing
                else "every process is here: playing"
            )
            node.play()
            if ref_sub is not None:  # the referee's last frame may come after our own last tick
                await_last_referee(last_ref, cfg.total_ticks, LAST_REFEREE_S)
        finally:
            if ref_sub is not None:
                ref_sub.undeclare()
            transport.close()
    tell(final_score(last_ref, cfg))
    log.debug("%s done", pid)
    return 0


def observer_settings(
    pid: ProcessId, cfg: MatchConfig, match: str, record: str | None, host: str, port: int | None
) -> tuple[MatchConfig, dict[str, object]]:
    """The recorder's and the viewer's own settings: (the configuration as they see it, their extra arguments)."""
    if pid.kind == "recorder":
        if not cfg.tap:
            raise ConfigError(f"match {match!r} does not record: start it with --record FILE.mcap")
        if not record:
            raise ConfigError("arena run recorder needs --record FILE.mcap")
        return cfg, {"path": record}  # the path reaches the recorder only
    if pid.kind == "viewer":
        # A viewer attached by hand to a match started without --live watches
        # only (the engine has no pacer to pause) and nobody waits for it.
        attached = cfg.live < 0
        live = port if port is not None else (8765 if attached else cfg.live)
        return cfg.replace(live=live), {"host": host, "attached": attached}
    return cfg, {}


LAST_REFEREE_S = 1.0  # [s] wall: a process started by hand waits up to this long for the referee's last frame


def await_last_referee(last_ref: list[bytes], total_ticks: int, timeout: float) -> None:
    """Until the newest referee frame in `last_ref` is of tick `total_ticks` (END_GAME), at most `timeout`.

    The final score line of a process started by hand reports it: a robot's own last tick may come
    before the referee's last frame arrives (it said `match over at tick 295 (SECOND_HALF)`)."""
    decode = msgspec.msgpack.Decoder(Referee).decode
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        newest = last_ref[-1:]  # the subscriber replaces it from zenoh's thread
        try:
            if newest and decode(newest[0]).tick >= total_ticks:
                return
        except (msgspec.DecodeError, msgspec.ValidationError):
            return  # final_score says so
        time.sleep(0.01)


def final_score(last_ref: list[bytes], cfg: MatchConfig) -> str:
    if not last_ref:
        return "match over (no referee message seen: the score is in the match's output)"
    try:
        ref = msgspec.msgpack.Decoder(Referee).decode(last_ref[-1])
    except (msgspec.DecodeError, msgspec.ValidationError):
        return "match over (the last referee message was unreadable)"
    return f"match over at tick {ref.tick} ({ref.stage}): a ({cfg.home}) {ref.score_a} : {ref.score_b} b ({cfg.away})"


def main_guarded(fn, *args) -> int:
    """Turn the expected failures into one-line messages and exit codes."""
    try:
        return fn(*args)
    except ConfigError as exc:
        print(f"arena run: error: {exc}", file=sys.stderr)
        return 2
    except StartupError as exc:  # the match or its router never came: a matter of addresses and timing
        print(f"arena run: error: {exc}", file=sys.stderr)
        return 2
    except zenoh.ZError as exc:
        from arena.runtime.session import zenoh_reason

        print(f"arena run: zenoh error: {zenoh_reason(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("arena run: interrupted", file=sys.stderr)
        return 130
