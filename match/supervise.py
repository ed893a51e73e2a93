"""Supervising a match the launcher started: every process's `Summary`, verified
and collected within bounds, and every way a process can end noted by name."""

from __future__ import annotations

import functools
import sys
import threading
import time
from collections import Counter
from dataclasses import dataclass

import msgspec

from arena.config import MatchConfig
from arena.match.children import Child, MatchError
from arena.match.faults import VOIDING, exit_reason, lapses
from arena.match.result import Collected
from arena.match.witness import Witness
from arena.runtime.transport import ZenohTransport
from arena.schemas.keys import SPOOFING, Keys
from arena.schemas.messages import Referee, Summary


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
        self._came = threading.Event()  # something came on a summary key since the last `wait`
        ring = getattr(transport, "keyring", None)
        for name in names:
            key = keys.summary(name)
            verify = ring.verifier(name, key) if ring is not None else None
            on_forged = functools.partial(self.count, name, "no valid MAC")
            # A ring, never a FIFO: a flood of forged summaries must not fill a queue that blocks the
            # router's own receive thread (its peers' leases then lapsed); a genuine summary is put
            # again every 0.25 s until acknowledged, so one pushed out of the ring comes back.
            self.channels[name] = transport.subscribe(key, latest=RING, verify=verify, on_forged=on_forged)
            # Only a wake-up (whatever it is, `poll` judges it): supervision sleeps until then.
            transport.subscribe_callback(key, self._wake)
        transport.declare_alive(keys.collector())

    def _wake(self, payload: bytes) -> None:
        self._came.set()

    def wait(self, timeout: float) -> None:
        """Sleep up to `timeout`, less if something comes on a summary key meanwhile."""
        self._came.wait(timeout)
        self._came.clear()

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


def watch_spoofing(transport: ZenohTransport, keys: Keys, announce) -> None:
    """Print `possible spoofing on KEY` once per key, when a process first declares that it dropped a
    forged frame on KEY, or counted a conflicting one (`spoofing/<user>/<key>`). Declared before any
    process can play: a token declared while this subscription was being made could go unseen."""
    spoofed: set[str] = set()

    def on_spoofing(key: str, alive: bool) -> None:
        user, _, rel = key.split(f"/{SPOOFING}/", 1)[-1].partition("/")
        if alive and rel and rel not in spoofed and len(spoofed) < 100:  # a stranger may declare these too
            spoofed.add(rel)
            if announce is not None:
                announce(f"possible spoofing on {rel} (forged or conflicting frames, seen by {user.replace('-', '/')})")

    transport.watch_alive(keys.spoofing_all(), on_spoofing)


# [frames] what the launcher's own subscriptions (summaries, referee) hold between two polls at most
RING = 1024


def supervision_deadline(cfg: MatchConfig) -> float:
    """[s] wall: the longest a whole match may take before the launcher gives up.

    Start-up (`startup_timeout`), the match at a real-time factor of at least
    0.2 in lockstep (1 in real time), one last-resort watchdog wait
    (`wait_timeout`) and the summaries' grace (`summary_grace`, `finish_grace`).
    2 x 60 s in lockstep: 30 + 600 + 60 + 16 = 706 s; the typical match takes a
    tenth of that.
    """
    t = cfg.timing
    play = cfg.total_ticks * t.dt * (1.0 if cfg.realtime else 5.0)
    return t.startup_timeout + play + t.wait_timeout + t.summary_grace + t.finish_grace


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
    on; a failed engine or referee makes it void at once (match/faults.py).
    `announce(text)` hears of each failure when it happens (a viewer that
    could not serve, say), with the last line of the process's log.
    """
    decode_summary = msgspec.msgpack.Decoder(Summary).decode
    decode_ref = msgspec.msgpack.Decoder(Referee).decode
    sums = collector
    # The referee's frames, MAC checked: the progress bar, and what a void match played (`last_referee`).
    ring = getattr(transport, "keyring", None)
    verify = ring.verifier("referee", keys.key("referee")) if ring is not None else None
    refs = transport.subscribe(keys.key("referee"), latest=RING, verify=verify)  # only the newest matters
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
    # [s] a process whose liveliness token vanished, or that exited, gets this long for its summary.
    grace = cfg.timing.summary_grace

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

    def take_referee() -> bool:
        """Keep the newest referee frame that came; whether one did."""
        last = None
        while (r := refs.try_recv()) is not None:
            last = r
        if last is None:
            return False
        try:
            got.last_referee = decode_ref(last)
        except (msgspec.DecodeError, msgspec.ValidationError):
            return False
        return True

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
            if take_referee():
                progress.update(got.last_referee)
            now = time.monotonic()
            for name in sorted(waiting - set(got.summaries)):
                c = by_name.get(name)
                code = c.popen.poll() if c is not None else None
                if code is not None:
                    seen = exit_seen.setdefault(name, now)
                    if code != 0:
                        fail(name, exit_reason(code), got.crashed)
                    elif now - seen > grace:
                        fail(name, "exited without a summary", got.crashed)
                elif name in gone_at and now - gone_at[name] > grace:
                    what = "stopped responding" if c is not None else "left"
                    fail(name, f"{what}: its liveliness token vanished before its summary", got.lost)
            left = waiting - set(got.summaries)
            if engine_done and left and not got.void:
                # The engine has played its last tick. A process that alone is still
                # missing has every input it will ever get; several may wait on each
                # other, at worst for one last-resort watchdog wait.
                finish = cfg.timing.finish_grace
                bound = finish if len(left) == 1 else cfg.timing.wait_timeout + finish
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
            # failed child: a slow poll leaves the two cores to the match. A summary
            # wakes it at once, and they all come within a few ms of each other:
            # poll fast then.
            sums.wait(0.01 if got.summaries else 0.1)
    take_referee()
    for name in list(gone_at):
        if name not in got.summaries and name not in got.lost and name not in got.crashed and name in expected:
            got.lost[name] = "stopped responding: its liveliness token vanished before its summary"
    failed, got.lapsed = lapses(lost_once & set(expected), got.summaries)
    for name in sorted(failed):
        # Back in time for its summary, but its peers gave up on it meanwhile; what it
        # says of them (everyone vanished from its view) is no evidence.
        got.lost.setdefault(name, "stopped responding for a while: its liveliness token vanished mid-match")
    got.ended = time.monotonic()
    return got
