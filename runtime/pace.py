"""Pacing a lockstep match for a live viewer: real-time speed, pause, step.

`arena match --live` starts a viewer (processes/viewer.py); in lockstep the
engine then waits on a `Pacer` before each tick, as it waits on a link: the
lockstep loop yields `(pacer, k)`, and the pacer is ready for tick k when

* the match is not paused (or a step request still covers k), and
* with a pace p > 0, the wall clock has reached `anchor + (k - k0) * dt / p`.

The pacer only ever delays a tick; what the engine computes and sends at tick
k is the same whenever it runs, so pacing and pausing never change a digest.
The wall clock (the engine's `Clock`, runtime/clock.py) is read for waiting
only, never for behaviour.

The viewer sends `Control` frames on `arena/<m>/control`, with its MAC: the
engine takes only the viewer's (processes/engine.py), and hands them to
`control`. A frame's `seq` must be above the last one's and at most
`SEQ_WINDOW` past it (the viewer counts up by one per change), so not even a
frame that got through could hold the sequence out of the viewer's reach; and
no pause outlasts `wait_timeout`: the pacer then gives up and plays on
(`give_up`), so a paused match still ends within its wall-clock bounds. In reactive lockstep (runtime/drivers.py, `Reactor`) the
loop runs in zenoh's callbacks, so nothing may sleep there: a small thread of
the pacer calls `poke` (the Reactor's) when a tick's time has come, and a
control frame pokes it too. In pull mode `sync` blocks on the main thread.

`WireGate`: an unpaced live match puts only every Nth `world` frame on the
wire (`LIVE_WORLD_HZ` of match time), and the last frame whenever the pacer
holds the match (paused, stepped, paced, the end), so a viewer always shows
the tick the engine holds. Every frame is still encoded and digested
(runtime/lockstep.py `Outbound.send`): what goes on the wire changes no digest.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable

from arena.runtime.clock import MONOTONIC, Clock
from arena.runtime.lockstep import EVERY_TICK
from arena.schemas.messages import Control

BEHIND_S = 0.25  # [s] wall: further behind its schedule than this, the pacer restarts it from now (no sprint)
POLL_S = 0.05  # [s] wall: pull mode, how often a paused engine looks for control frames
LIVE_WORLD_HZ = 10.0  # [Hz] match time: world frames an unpaced live match puts on the wire
SEQ_WINDOW = 1000  # [-] a control frame's seq may be at most this far past the last one's


def _nowhere(payload: bytes) -> None:
    return None


class WireGate:
    """A put function that passes every `every`-th payload and holds the others; `flush` puts the held one.

    Called from one thread at a time: the engine's loop (publish, and `Pacer.ready`'s hold).
    """

    __slots__ = ("_put", "every", "_n", "_held", "passed")

    def __init__(self, every: int):
        self._put: Callable[[bytes], None] = _nowhere
        self.every = max(1, every)
        self._n = 0
        self._held: bytes | None = None
        self.passed = 0

    def wrap(self, put: Callable[[bytes], None]) -> WireGate:
        """For `Outbound.put_through`: this gate in front of `put`."""
        self._put = put
        return self

    def __call__(self, payload: bytes) -> None:
        if self._n % self.every == 0:
            self._held = None
            self._put(payload)
            self.passed += 1
        else:
            self._held = payload
        self._n += 1

    def flush(self) -> None:
        if self._held is not None:
            payload, self._held = self._held, None
            self._put(payload)
            self.passed += 1


class Pacer:
    """Duck-types a lockstep `Inbound` for the drivers (`ready`, `sync`, `drain`, `woken`, `paired`,
    `sender`, `sender_gone`, `give_up`; runtime/drivers.py)."""

    sender = "viewer"
    key = "control"
    paired = False  # a held tick is a wait like any other: the engine puts its held `sense` batches first
    schedule = EVERY_TICK  # the Reactor's bound on a wait names the tick waited for (runtime/drivers.py `_look`)
    ready_below = -1  # no bound kept: a driver asks `ready(k)` (runtime/drivers.py `advance`)

    def __init__(
        self,
        dt: float,
        pace: float,
        log: logging.Logger | None = None,
        timeout: float = math.inf,
        clock: Clock = MONOTONIC,
    ):
        self.clock = clock  # the wall time it paces to (a test's ManualClock)
        self.dt = dt
        self.pace = pace
        self.timeout = timeout  # [s] wall: the longest pause in pull mode (`sync`); the Reactor bounds its own waits
        self.log = log or logging.getLogger("arena.pace")
        self.paused = False
        self.until = -1  # paused: ticks up to this one may still play (steps)
        self.played = -1  # the last tick this pacer let through
        self.woken = False
        self.dead = False
        self._anchor: tuple[float, int] | None = None  # (wall time, tick) the schedule counts from
        self._due: float | None = None  # reactive: the wall time at which to poke
        self._seq = -1
        self._cond = threading.Condition()
        self._poke: Callable[[], None] | None = None
        self._stop = False
        self._thread: threading.Thread | None = None
        self._pending: Callable[[], bytes | None] | None = None
        self._take: Callable[[bytes], None] | None = None
        self.controls = 0  # control frames applied
        self.on_hold: Callable[[], None] | None = None  # called (on the loop's thread) whenever a tick is held

    # ------------------------------------------------------------- the gate
    def ready(self, k: int) -> bool:
        if self._gate(k):
            return True
        if self.on_hold is not None:
            self.on_hold()
        return False

    def _gate(self, k: int) -> bool:
        with self._cond:
            if self.paused and k > self.until:
                self._due = None
                return False
            if self.pace > 0.0 and not self.paused:
                now = self.clock.monotonic()
                if self._anchor is None:
                    self._anchor = (now, k)
                t0, k0 = self._anchor
                due = t0 + (k - k0) * self.dt / self.pace
                if due > now:
                    self._due = due
                    self._cond.notify_all()
                    return False
                if now - due > BEHIND_S:
                    self._anchor = (now, k)
            self._due = None
            self.played = k
            return True

    @property
    def last_seen(self) -> int:
        return self.played

    def sync(self, k: int) -> None:
        """Pull mode: block until tick k may play, at most `timeout` seconds (then `give_up`)."""
        since = self.clock.monotonic()
        while True:
            if self._pending is not None:
                while (raw := self._pending()) is not None:
                    (self._take or self.control_raw)(raw)
            if self.ready(k):
                return
            if self.clock.monotonic() - since >= self.timeout:
                self.give_up(f"held for {self.timeout:g} s before tick {k}")
                continue
            with self._cond:
                left = POLL_S if self._due is None else min(POLL_S, self._due - self.clock.monotonic())
                if left > 0:
                    self.clock.wait_on(self._cond, left)

    def drain(self) -> None:
        """Nothing to take in: control frames come through `pull_from` or `control`."""

    def sender_gone(self) -> bool:
        return False

    def give_up(self, why: str) -> None:
        """The Reactor's bound on one wait: a pause longer than wait_timeout resumes the match."""
        self.log.warning("paused for too long (%s): playing on", why)
        with self._cond:
            self.paused = False
            self._anchor = None

    # --------------------------------------------------------------- control
    def control(self, c: Control) -> tuple[str, str] | None:
        """Apply one frame; returns (reason, detail) if it is refused (a repeat or an old one is ignored)."""
        with self._cond:
            if c.seq <= self._seq:
                return None  # a repeat (the state the engine asked for, then put) or an old frame
            if c.seq > max(self._seq, 0) + SEQ_WINDOW:
                return "out-of-sequence", f"seq {c.seq} jumps more than {SEQ_WINDOW} past {self._seq}"
            self._seq = c.seq
            if c.pace >= 0.0:
                self.pace = c.pace
            if c.paused and not self.paused:
                self.until = self.played
            self.paused = c.paused
            if c.paused and c.step > 0:
                self.until = max(self.until, self.played) + c.step
            self._anchor = None  # the schedule restarts from the next tick
            self.controls += 1
            self._cond.notify_all()
        if self._poke is not None:
            self._poke()
        return None

    def control_raw(self, raw: bytes, decode=None) -> tuple[str, str] | None:
        """Apply one wire frame; returns (reason, detail) if it was rejected, or None."""
        import msgspec

        try:
            c = (decode or msgspec.msgpack.Decoder(Control).decode)(raw)
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            return "malformed", str(exc)[:120]
        return self.control(c)

    # ---------------------------------------------------------------- modes
    def pull_from(self, recv: Callable[[], bytes | None], take: Callable[[bytes], None] | None = None) -> None:
        """Pull mode: `sync` drains `recv` (a channel's try_recv) for control frames, each to `take`
        (which applies it and counts a rejection; default: `control_raw`)."""
        self._pending = recv
        self._take = take

    def start(self, poke: Callable[[], None]) -> None:
        """Reactive mode: a thread pokes the loop when a paced tick is due."""
        self._poke = poke
        self._thread = threading.Thread(target=self._run, name="pacer", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while True:
            with self._cond:
                if self._stop:
                    return
                due = self._due
                if due is None:
                    self.clock.wait_on(self._cond, 0.5)
                    continue
                left = due - self.clock.monotonic()
                if left > 0:
                    self.clock.wait_on(self._cond, left)
                    continue
                self._due = None
            self._poke()

    def stop(self) -> None:
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
