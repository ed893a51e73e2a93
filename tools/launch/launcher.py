"""`arena match`: one match as a group of OS processes, supervised.

The launcher hosts the match's zenoh router (a unix socket in a private temp
dir unless `--listen` says otherwise), starts every process with the same
`arena run <kind> ...` command a user would type, waits for each one's
`Summary`, and assembles the match result. Ctrl-C, or any child exiting with
an error, ends the whole group; children also die with the launcher
(PR_SET_PDEATHSIG), so no orphan survives.
"""

from __future__ import annotations

import compileall
import ctypes
import functools
import hashlib
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import msgspec
import zenoh

from arena.runtime.config import MatchConfig, ProcessId
from arena.runtime.credentials import Secrets, drop_puts_towards, loopback_only, new_zid, secure_endpoint
from arena.runtime.session import NetConfig, open_session
from arena.runtime.stats import percentile
from arena.runtime.transport import ZenohTransport
from arena.schemas.keys import Keys, routes
from arena.schemas.messages import Referee, Summary
from arena.tools.launch import forkstart
from arena.tools.launch.faults import VOIDING, exit_reason
from arena.tools.launch.faults import outcome as match_outcome
from arena.tools.launch.run import Job
from arena.tools.launch.witness import Witness

_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """Runs in the child before exec: SIGKILL it if the launcher dies."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except OSError:
        pass


class MatchError(RuntimeError):
    """The match could not be played to the end; the message says why."""


class JoinError(MatchError):
    """An `--external` process never joined (a user's or a network's matter: exit 2)."""


def lan_addresses() -> list[str]:
    """This machine's IPv4 addresses other than loopback and link-local (what a robot on the LAN can reach)."""
    import fcntl
    import socket
    import struct

    found: list[str] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for _, name in socket.if_nameindex():
            try:
                packed = fcntl.ioctl(s.fileno(), 0x8915, struct.pack("256s", name[:15].encode()))  # SIOCGIFADDR
            except OSError:
                continue  # no IPv4 address on this interface
            addr = socket.inet_ntoa(packed[20:24])
            if not addr.startswith(("127.", "169.254.")) and addr not in found:
                found.append(addr)
    return found


def robot_endpoints(endpoint: str) -> tuple[list[str], bool]:
    """The endpoints a process on another computer can connect to, and whether it needs `--mode client`.

    `tcp/0.0.0.0:P` (every interface) becomes one endpoint per LAN address; a
    loopback or unix-socket endpoint stays as it is, for a process on this
    machine, which can mesh with the others as a peer. A process on another
    computer cannot reach the others' loopback ports, so it talks through the
    router: `--mode client` (docs/architecture.md).
    """
    proto, _, address = endpoint.partition("/")
    host, _, port = address.rpartition(":")
    if proto == "unixsock-stream" or host.startswith(("127.", "localhost", "[::1]")):
        return [endpoint], False
    if host in ("0.0.0.0", "[::]"):
        lan = lan_addresses()
        if not lan:  # no network but loopback: only this machine can join
            return [f"{proto}/127.0.0.1:{port}"], False
        return [f"{proto}/{a}:{port}" for a in lan], True
    return [endpoint], True


class Joins:
    """Which processes of the match have their liveliness token (who is there), seen from the router."""

    def __init__(self, session, keys: Keys, external: set[ProcessId], announce) -> None:
        self.external = {str(p) for p in external}
        self.alive: set[str] = set()
        self.announce = announce or (lambda text: None)
        self._subs = []
        if self.external:
            self._subs.append(session.liveliness().declare_subscriber(keys.alive_all(), self._on_alive, history=True))
            self._subs.append(session.declare_subscriber(keys.refused_all(), self._on_refused))

    def _on_alive(self, sample) -> None:
        name = str(sample.key_expr).split("/alive/", 1)[-1]
        if sample.kind == zenoh.SampleKind.PUT:
            self.alive.add(name)
            if name in self.external:
                self.announce(f"external {name} joined")
        else:
            self.alive.discard(name)

    def _on_refused(self, sample) -> None:
        name = str(sample.key_expr).split("/refused/", 1)[-1]
        self.announce(
            f"refused a second {name}: one is already running ({sample.payload.to_bytes().decode(errors='replace')})"
        )

    def missing(self) -> list[str]:
        return sorted(self.external - self.alive)

    def wait(self, timeout: float, children: list[Child]) -> None:
        """Until every external process has joined; JoinError after `timeout`.

        The children wait as long at their start barrier, but their clocks
        start later (after spawn and imports), so this gives up first and the
        message names who never came. A child that fails meanwhile is
        supervise()'s to report.
        """
        deadline = time.monotonic() + timeout
        while self.missing() and all(c.popen.poll() is None for c in children):
            if time.monotonic() > deadline:
                raise JoinError(
                    f"external {', '.join(self.missing())} did not join within {timeout:g} s "
                    "(start it with the command printed above)"
                )
            time.sleep(0.1)

    def close(self) -> None:
        for sub in self._subs:
            sub.undeclare()


@dataclass
class Child:
    name: str
    pid: ProcessId
    popen: subprocess.Popen
    log_path: Path

    def tail(self, lines: int = 8) -> str:
        try:
            text = self.log_path.read_text(errors="replace").rstrip().splitlines()
        except OSError:
            return ""
        return "\n".join("    " + line for line in text[-lines:])


# The packages mapped to a directory of their own (pyproject.toml `package-dir`);
# their subpackages (arena.sim.physics, arena.strategies.iris, ...) live below them.
_PACKAGES = (
    "arena",
    "arena.runtime",
    "arena.processes",
    "arena.schemas",
    "arena.strategies",
    "arena.navigation",
    "arena.tools",
    "arena.sim",
    "arena.rules",
    "arena.recording",
)


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


def run_argv(job: Job) -> list[str]:
    """`python -m arena run ...`: the command that runs `job` in a fresh interpreter."""
    return [sys.executable, "-m", "arena", *job.argv()]


def spawn(name: str, pid: ProcessId, argv: list[str], log_dir: Path, env: dict[str, str] | None = None) -> Child:
    log_path = log_dir / (name.replace("/", "_") + ".log")
    fh = open(log_path, "wb")
    try:
        popen = subprocess.Popen(
            argv,
            stdin=subprocess.DEVNULL,
            stdout=fh,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # Ctrl-C reaches the launcher only; it stops the group
            preexec_fn=_die_with_parent,
            env=env,
        )
    finally:
        fh.close()
    return Child(name, pid, popen, log_path)


def stop_all(children: list[Child], grace: float = 3.0) -> None:
    for c in children:
        if c.popen.poll() is None:
            c.popen.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + grace
    for c in children:
        left = max(0.0, deadline - time.monotonic())
        try:
            c.popen.wait(timeout=left)
        except subprocess.TimeoutExpired:
            c.popen.kill()
            c.popen.wait()


@dataclass
class Progress:
    """Optional live progress (a rich bar on a terminal)."""

    total_ticks: int
    enabled: bool
    _bar: object = None
    _task: object = None
    score: tuple[int, int] = (0, 0)

    def __enter__(self) -> Progress:
        if self.enabled:
            from rich.progress import BarColumn, TextColumn, TimeRemainingColumn
            from rich.progress import Progress as RichProgress

            self._bar = RichProgress(
                TextColumn("[bold]match[/]"),
                BarColumn(),
                TextColumn("{task.fields[status]}"),
                TimeRemainingColumn(),
                transient=True,
            )
            self._bar.__enter__()
            self._task = self._bar.add_task("match", total=self.total_ticks, status="starting")
        return self

    def update(self, ref: Referee) -> None:
        if self._bar is not None:
            self._bar.update(
                self._task, completed=ref.tick, status=f"{ref.stage.lower():12s} {ref.score_a}:{ref.score_b}"
            )

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.__exit__(None, None, None)


@dataclass
class Collected:
    summaries: dict[str, Summary] = field(default_factory=dict)
    pids: dict[str, int] = field(default_factory=dict)
    forged: Counter = field(default_factory=Counter)  # rejected summaries per key
    started: float = 0.0
    ended: float = 0.0
    crashed: dict[str, str] = field(default_factory=dict)  # name -> why (exit code)
    lost: dict[str, str] = field(default_factory=dict)  # liveliness gone before the summary
    missing: dict[str, str] = field(default_factory=dict)  # no summary within the bound
    void: str = ""  # why the match is void, found while supervising


class Collector:
    """The summaries of a match, one subscription per process, each verified with that process's key.

    A Summary counts only if its MAC checks out (runtime/mac.py), it names the
    process whose key it is on, it is plausible, and it is the first one; any
    other counts under `forged` (the launcher's own counter, per key).
    """

    def __init__(self, transport: ZenohTransport, keys: Keys, names: list[str]):
        self.keys = keys
        self.forged: Counter[str] = Counter()
        self.channels = {}
        ring = getattr(transport, "keyring", None)
        for name in names:
            key = keys.summary(name)
            verify = ring.verifier(name, key) if ring is not None else None
            on_forged = functools.partial(self.count, name, "no valid MAC")
            self.channels[name] = transport.subscribe(key, verify=verify, on_forged=on_forged)
        transport.declare_alive(keys.collector())

    def count(self, name: str, why: str) -> None:
        key = f"summary/{name}"
        self.forged[key] += 1
        if self.forged[key] <= 3:
            print(f"arena match: warning: forged {key} rejected ({why})", file=sys.stderr, flush=True)

    def poll(self):
        for name, ch in self.channels.items():
            while (raw := ch.try_recv()) is not None:
                yield name, raw


def implausible(s: Summary, name: str, cfg: MatchConfig, names: list[str]) -> str | None:
    """Why a Summary cannot be the one `name` sent, or None."""
    if s.process != name or name not in names:
        return f"it names {s.process!r}, not a process of this match"
    if not 0 <= s.tick <= cfg.total_ticks:
        return f"tick {s.tick} outside 0..{cfg.total_ticks}"
    if s.sent != sum(s.sent_by_key.values()) or s.sent < 0:
        return "sent differs from the sum of sent_by_key"
    if s.rejected != sum(s.rejected_reasons.values()) or s.rejected < 0:
        return "rejected differs from the sum of rejected_reasons"
    if not set(s.dead) <= set(names) or name in s.dead:
        return "dead names unknown processes"
    if len(s.digest) != 32 or any(c not in "0123456789abcdef" for c in s.digest):
        return "digest is not 32 hex digits"
    return None


def open_collector(transport: ZenohTransport, keys: Keys, names: list[str]) -> Collector:
    """Subscribe to every process's summary and announce a collector, before any process starts."""
    return Collector(transport, keys, names)


# [s] a process whose liveliness token vanished, or that exited, gets this long
# for its summary to arrive (a summary is re-sent for up to 5 s until acked).
SUMMARY_GRACE = 6.0
# [s] once every other process has finished, the last ones must finish within this.
FINISH_GRACE = 10.0


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


def supervision_deadline(cfg: MatchConfig) -> float:
    """[s] wall: the longest a whole match may take before the launcher gives up.

    Start-up (`startup_timeout`), the match at a real-time factor of at least
    0.2 in lockstep (1 in real time), one last-resort watchdog wait
    (`wait_timeout`) and the summaries' grace. 2 x 60 s in lockstep: 30 + 600 +
    60 + 16 = 706 s; the typical match takes a tenth of that.
    """
    t = cfg.timing
    play = cfg.total_ticks * t.dt * (1.0 if cfg.realtime else 5.0)
    return t.startup_timeout + play + t.wait_timeout + SUMMARY_GRACE + FINISH_GRACE


def supervise(  # noqa: C901, PLR0912, PLR0915 - one supervision loop: every way a process can end
    transport: ZenohTransport,
    collector,
    keys: Keys,
    cfg: MatchConfig,
    children: list[Child],
    expected: list[str],
    progress: Progress,
    timeout: float | None = None,
    strict: bool = False,
    witness: Witness | None = None,
    announce=None,
) -> Collected:
    """Wait for every expected summary, within bounds; note every failure by name.

    `strict`: the first child to fail ends the match (MatchError), as for CI.
    Otherwise a failed team process or recorder is a fault and the match plays
    on; a failed engine or referee makes it void at once (tools/launch/faults.py).
    `announce(text)` hears of each failure when it happens (a viewer that
    could not serve, say), with the last line of the process's log.
    """
    decode_summary = msgspec.msgpack.Decoder(Summary).decode
    decode_ref = msgspec.msgpack.Decoder(Referee).decode
    sums = collector
    refs = transport.subscribe(keys.key("referee")) if progress.enabled else None
    got = Collected(started=time.monotonic())
    deadline = got.started + (timeout if timeout is not None else supervision_deadline(cfg))
    waiting = set(expected)
    gone_at: dict[str, float] = {}  # liveliness token vanished (wall time)

    lost_once: set[str] = set()  # lost its token mid-match, even if it came back (a 10 s SIGSTOP)

    def on_alive(key: str, alive: bool) -> None:
        peer = key.split("/alive/", 1)[-1]
        if alive:
            gone_at.pop(peer, None)
        elif peer not in got.summaries:
            gone_at.setdefault(peer, time.monotonic())
            lost_once.add(peer)

    transport.watch_alive(keys.alive_all(), on_alive)
    by_name = {c.name: c for c in children}
    exit_seen: dict[str, float] = {}
    engine_done = last_summary = 0.0

    def fail(name: str, why: str, into: dict[str, str]) -> None:
        c = by_name.get(name)
        if strict:
            pid = f" (pid {c.popen.pid})" if c is not None else ""
            raise MatchError(f"{name}{pid} {why}:\n{c.tail() if c else ''}")
        into[name] = why
        waiting.discard(name)
        voids = name.split("/")[0] in VOIDING and not got.void
        if voids:
            got.void = f"{name} {why}"
        if announce is not None:
            last = c.tail(1).strip() if c is not None else ""
            then = "the match is void" if voids else "the match plays on"
            announce(f"{name} {why}; {then}" + (f" (its log: {last})" if last else ""))

    got.forged = sums.forged
    acks: dict[str, object] = {}
    with progress:
        while waiting - set(got.summaries) and not got.void:
            polled = False
            for name, raw in sums.poll():
                polled = True
                try:
                    s = decode_summary(raw)
                except (msgspec.DecodeError, msgspec.ValidationError):
                    sums.count(name, "not a Summary")
                    continue
                first = got.summaries.get(name)
                if first is not None:
                    if msgspec.msgpack.encode(first) != msgspec.msgpack.encode(s):
                        sums.count(name, "a second, different summary")
                    else:
                        acks[name](b"ack")  # the sender repeats it until acknowledged
                    continue
                why = implausible(s, name, cfg, expected)
                if why is None and witness is not None:
                    why = witness.check(name, s.digest, s.dead)
                if why is not None:
                    sums.count(name, why)
                    continue
                got.summaries[name] = s
                last_summary = time.monotonic()
                if name == "engine":
                    engine_done = time.monotonic()
                acks[name] = transport.publisher(keys.ack(name))
                acks[name](b"ack")
            if polled:
                continue
            if refs is not None:
                last = None
                while (r := refs.try_recv()) is not None:
                    last = r
                if last is not None:
                    try:
                        progress.update(decode_ref(last))
                    except (msgspec.DecodeError, msgspec.ValidationError):
                        pass
            now = time.monotonic()
            for name in sorted(waiting - set(got.summaries)):
                c = by_name.get(name)
                code = c.popen.poll() if c is not None else None
                if code is not None:
                    seen = exit_seen.setdefault(name, now)
                    if code != 0:
                        fail(name, exit_reason(code), got.crashed)
                    elif now - seen > SUMMARY_GRACE:
                        fail(name, "exited without a summary", got.crashed)
                elif name in gone_at and now - gone_at[name] > SUMMARY_GRACE:
                    what = "stopped responding" if c is not None else "left"
                    fail(name, f"{what}: its liveliness token vanished before its summary", got.lost)
            left = waiting - set(got.summaries)
            if engine_done and left and not got.void:
                # The engine has played its last tick. A process that alone is still
                # missing has every input it will ever get; several may wait on each
                # other, at worst for one last-resort watchdog wait.
                bound = FINISH_GRACE if len(left) == 1 else cfg.timing.wait_timeout + FINISH_GRACE
                if now - max(engine_done, last_summary) > bound:
                    for name in sorted(left):
                        fail(name, f"sent no summary within {bound:g} s of the match's end", got.missing)
            if now > deadline and not got.void:
                missing = sorted(waiting - set(got.summaries))
                if strict or timeout is not None:
                    waited = deadline - got.started
                    raise MatchError(f"match timed out after {waited:g} s waiting for: {', '.join(missing)}")
                got.void = f"no result within the supervision deadline ({deadline - got.started:g} s)"
                for name in missing:
                    got.missing[name] = "no summary by the supervision deadline"
            # Nothing to do while the match plays but show progress and notice a
            # failed child: a slow poll leaves the two cores to the match. The
            # summaries all come within a few ms of each other: poll fast then.
            time.sleep(0.01 if got.summaries else 0.1)
    for name in list(gone_at):
        if name not in got.summaries and name not in got.lost and name not in got.crashed and name in expected:
            got.lost[name] = "stopped responding: its liveliness token vanished before its summary"
    for name in sorted(lost_once & set(expected)):
        # Back in time for its summary, but its peers lost it meanwhile; what it
        # says of them (everyone vanished from its view) is no evidence.
        got.lost.setdefault(name, "stopped responding for a while: its liveliness token vanished mid-match")
    got.ended = time.monotonic()
    return got


def assemble(cfg: MatchConfig, got: Collected, wall_total: float, children: list[Child], record: str = "") -> dict:
    """The match result (what `arena match --json` prints)."""
    # The recorder and the viewer send no data, and the RefBox bridge's worldstates are
    # what the teams sent (no process's input): the digest is the same with or without them.
    order = [str(p) for p in cfg.processes() if p.kind not in ("recorder", "refbox", "viewer")]
    sums = got.summaries
    combined = hashlib.blake2b(digest_size=16)
    for name in order:
        if name in sums:
            combined.update(name.encode() + b"=" + sums[name].digest.encode() + b";")
    referee = sums.get("referee")
    engine = sums.get("engine")
    links: dict[str, dict] = {}
    for name in order:
        s = sums.get(name)
        if s is None:
            continue
        for cls, agg in s.links.items():
            acc = links.setdefault(cls, {"sent": 0, "dropped": 0, "_delays": []})
            acc["sent"] += int(agg["frames"])
            acc["dropped"] += int(agg["dropped"])
            acc["_delays"].extend(s.delays_ms.get(cls, []))
    for acc in links.values():
        d = sorted(acc.pop("_delays"))
        acc["drop_rate"] = round(acc["dropped"] / acc["sent"], 5) if acc["sent"] else 0.0
        acc["delay_ms_mean"] = round(sum(d) / len(d), 3) if d else 0.0
        acc["delay_ms_p95"] = round(percentile(d, 95), 3)
    rejected = Counter()
    for s in sums.values():
        rejected.update(s.rejected_reasons)
    if got.forged:
        rejected["forged"] += sum(got.forged.values())
    pid_of = {c.name: c.popen.pid for c in children}
    processes = []
    for p in cfg.processes():
        name = str(p)
        s = sums.get(name)
        processes.append(
            {
                "kind": p.kind,
                "team": p.team or None,
                "robot": p.robot if p.kind == "robot" else None,
                "pid": s.pid if s is not None else pid_of.get(name),
                "external": p.short in cfg.external or name in cfg.external,
                "tick_us_median": round(s.tick_us[0], 1) if s and s.tick_us else None,
                "tick_us_p95": round(s.tick_us[1], 1) if s and s.tick_us else None,
                "cpu_s": round(sum(s.cpu_s), 3) if s and s.cpu_s else None,
            }
        )
    score = list(referee.extra.get("score", [0, 0])) if referee else [0, 0]
    sent_by_key: dict[str, int] = {}
    for name in order:
        if name in sums:
            for key, n in sums[name].sent_by_key.items():
                sent_by_key[key] = sent_by_key.get(key, 0) + n
    recorder = sums.get("recorder")
    ticks = engine.tick if engine else 0
    sim_seconds = ticks * cfg.timing.dt
    # Simulation speed is measured by the engine from its start barrier to its
    # last tick; process start-up is reported apart (wall_seconds).
    play = max(1e-9, engine.wall_s if engine and engine.wall_s > 0 else got.ended - got.started)
    honest = match_outcome(cfg, sums, got.crashed, got.lost, got.missing, got.void)
    recording = recorder.extra if recorder else None
    if cfg.tap and recorder is None:
        why = next((f["reason"] for f in honest["faults"] if f["process"] == "recorder"), "no summary")
        recording = {"path": record, "complete": False, "error": f"the recorder failed: {why}"}
    return {
        "outcome": honest["outcome"],
        "void": honest["void"],
        "outcome_reasons": honest["outcome_reasons"],
        "home": cfg.home,
        "away": cfg.away,
        "score": score,
        "seed": cfg.seed,
        "robots": cfg.robots,
        "half_time": cfg.half_time,
        "link": cfg.link,
        "realtime": cfg.realtime,
        "engine": "processes",  # tools/launch/inprocess.py says "inprocess"
        "ticks": ticks,
        "sim_seconds": round(sim_seconds, 3),
        "wall_seconds": round(wall_total, 3),
        "play_wall_seconds": round(play, 3),
        "rtf": round(sim_seconds / play, 2),
        "digest": combined.hexdigest(),
        "process_digests": {name: sums[name].digest for name in order if name in sums},
        "processes": processes,
        "links": links,
        "events": dict(sorted(referee.extra.get("events", {}).items())) if referee else {},
        "distance_m": engine.extra.get("distance_m", {}) if engine else {},
        "parked": engine.extra.get("parked", {}) if engine else {},
        "sent_off": engine.extra.get("sent_off", []) if engine else [],  # cards and REPAIR_OUT (docs/rules.md)
        "rejected": sum(rejected.values()),
        "rejected_reasons": dict(rejected),
        "dead": honest["dead"],
        "faults": honest["faults"],
        "conflicts": honest["conflicts"],
        "forged_summaries": dict(sorted(got.forged.items())),
        "sent_by_key": dict(sorted(sent_by_key.items())),
        "recording": recording,
        "refbox": sums["refbox"].extra if "refbox" in sums else None,
        "refbox_follow": referee.extra.get("refbox_follow") if referee else None,
        "referee_log": referee.extra.get("log", []) if referee else [],
    }


def instructions(
    external: list[ProcessId],
    match: str,
    endpoint: str,
    record: str = "",
    credentials: dict[str, Path] | None = None,
    secure: bool = False,
) -> str:
    """What to type on the robot's computer: a command per --external process, with an address it can reach."""
    endpoints, client = robot_endpoints(endpoint)
    n = len(external)
    lines = [f"waiting for {n} external process{'es' if n != 1 else ''}; start {'each' if n != 1 else 'it'} with:"]
    for p in external:
        cred = str(credentials[str(p)]) if credentials else None
        argv = run_job(p, match, endpoints[0], record=record, credentials=cred).argv()
        if client and not secure:  # a secure match's credentials file says client mode
            argv += ["--mode", "client"]
        lines.append("  arena " + " ".join(argv))
    if credentials:
        lines.append("  (--credentials: that process's own key; copy the file to its computer and to nobody else)")
    if len(endpoints) > 1:
        lines.append(f"  (this machine is also reachable as: {', '.join(e.split('/', 1)[1] for e in endpoints[1:])})")
    return "\n".join(lines)


def startup_seconds(summaries: dict[str, Summary], launched: float) -> float | None:
    """Launch (`play_match` called) to the engine's first tick, from the engine's Summary."""
    engine = summaries.get("engine")
    started = engine.extra.get("play_started", 0.0) if engine is not None else 0.0
    return round(started - launched, 3) if started else None


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
) -> dict:
    """Play one match as separate processes and return its result dict.

    `record`: an MCAP path; it reaches the recorder's argv only, the other
    processes see `cfg.tap`. `announce(text)` is called with instructions for
    `--external` processes.
    `secure`: authenticated principals, access control and TLS (runtime/acl.py,
    runtime/credentials.py); None means on whenever `listen` is not loopback.
    `credentials`: the directory for every principal's credentials file
    (default: the match's private temp dir).
    A failed process is a fault in the result (`outcome`, `faults`: see
    tools/launch/faults.py); with `strict`, it raises MatchError instead, as does a
    match that cannot start.
    """
    t_start = time.monotonic()
    launched = time.time()
    compile_sources()
    cfg = cfg.replace(tap=bool(record))
    match = match or new_match_id(cfg.seed)
    keys = Keys(match)
    tmp = Path(tempfile.mkdtemp(prefix="arena-"))
    endpoint = listen or f"unixsock-stream/{tmp}/router.sock"
    secure = (not loopback_only(listen)) if secure is None else secure
    tls = False
    if secure:
        endpoint, tls = secure_endpoint(endpoint)
    connect = endpoint.replace("0.0.0.0", "127.0.0.1").replace("[::]", "[::1]")
    cfg_path = tmp / "config.json"
    cfg_path.write_text(cfg.to_json())
    logs = Path(log_dir) if log_dir else tmp
    logs.mkdir(parents=True, exist_ok=True)
    names = [str(p) for p in cfg.processes()]
    secrets = Secrets.new(match, cfg.robots, names, secure, tls=tls)
    external = {ProcessId.parse(e) for e in cfg.external}
    if secure:  # the viewer is served with DROP (Secrets.router_settings)
        more: dict[str, dict] = {}
        router_extra = tuple(secrets.router_settings(tmp))
    else:
        router_zid = new_zid()
        ext = {str(e) for e in external}
        more = {
            str(p): relay_safe(router_zid, str(p), match, cfg.robots, ext) for p in cfg.processes() if p not in external
        }
        router_extra = (("id", json.dumps(router_zid)), *SPECTATOR_SAFE)
    cred_paths = secrets.write(Path(credentials) if credentials else tmp / "credentials", more)
    children: list[Child] = []
    keep = False  # a failed match keeps its logs (and says where); anything else leaves nothing behind
    starter = None
    try:
        # Fork the processes before any zenoh session exists here (tools/launch/forkstart.py);
        # they open theirs once the router is up.
        local = [p for p in cfg.processes() if p not in external]
        starter = forkstart.starter(len(local), {p.kind for p in local}, {cfg.home, cfg.away})
        if starter is not None:
            for p in local:
                job = run_job(p, match, connect, str(cfg_path), record, live_host, str(cred_paths[str(p)]))
                log_path = logs / (str(p).replace("/", "_") + ".log")
                children.append(Child(str(p), p, starter.fork(job, log_path), log_path))  # type: ignore[arg-type]
        with open_session(NetConfig(mode="router", listen=(endpoint,), extra=router_extra)) as session:
            transport = ZenohTransport(session, secrets.keyring("launcher"))
            collector = open_collector(transport, keys, names)
            # An external's digest is recomputed from the frames it puts (tools/launch/witness.py).
            witness = Witness(transport, keys, cfg.robots, {str(p) for p in external}, cfg.timing.periods())
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
                transport.close()
        dead = {d for s in got.summaries.values() for d in s.dead} | set(got.lost) | set(got.missing)
        for c in children:
            if c.name in dead or got.void:
                continue  # hung, or a void match: stop_all below ends it
            try:
                c.popen.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        result = assemble(cfg, got, time.monotonic() - t_start, children, record)
        result["secure"] = secure
        result["digests_verified"] = witness.verified()
        result["startup_seconds"] = startup_seconds(got.summaries, launched)
        result["launch"] = "exec" if starter is None else starter.how
        engine = got.summaries.get("engine")
        result["play_started_unix"] = engine.extra.get("play_started") if engine is not None else None
        if result["outcome"] != "completed" and log_dir is None:
            keep = True  # a fault's evidence
            result["logs"] = str(tmp)
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
        if not keep:
            shutil.rmtree(tmp, ignore_errors=True)
