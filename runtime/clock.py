"""The one wall clock of a run, behind a small interface a test can drive (after trio's `MockClock`).

The runtime and the processes read wall time only to bound waits (the
`Watchdog`, the `Reactor`, the start barrier, a summary's delivery, the
recorder's idle bound, the RefBox bridge's start) and to keep pace with it (the
live pacer, runtime/pace.py; the real-time engine; the viewer): never for
simulation behaviour. Each reads the `Clock` its process was given
(`Peer.clock`); the real one is `MONOTONIC`, the only reader of `time` here. A test gives them a `ManualClock`
instead and moves its time on with `advance`, so a 60 s timeout takes no wall
time at all, and a test says which instant it checks instead of sleeping and
hoping the other thread got there.

A `ManualClock` knows which threads sleep on it. `advance(dt)` moves the
time, wakes every thread whose deadline has passed, and returns once each of
them sleeps on the clock again (or has ended): what a thread does at that
instant is done when `advance` returns. With `autojump` set, a sleeper whose wait has lasted that
many real seconds without anything happening moves the time to the earliest
deadline itself (trio's `autojump_threshold`), for a test that only needs the
waits to end.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Protocol


class Clock(Protocol):
    def monotonic(self) -> float:
        """Seconds, from an arbitrary start; never goes back."""
        ...

    def sleep(self, seconds: float) -> None: ...

    def wait(self, event: threading.Event, timeout: float) -> bool:
        """Wait until `event` is set (True) or `timeout` seconds of this clock have passed (False)."""
        ...

    def wait_on(self, cond: threading.Condition, timeout: float) -> None:
        """`cond.wait(timeout)` in this clock's time: the caller holds `cond`; a notify ends it early."""
        ...


class Monotonic:
    """The real clock: `time.monotonic`."""

    monotonic = staticmethod(time.monotonic)
    sleep = staticmethod(time.sleep)

    @staticmethod
    def wait(event: threading.Event, timeout: float) -> bool:
        return event.wait(timeout)

    @staticmethod
    def wait_on(cond: threading.Condition, timeout: float) -> None:
        cond.wait(timeout)


MONOTONIC = Monotonic()

POLL_S = 0.002  # [s] real: how often a sleeper on a ManualClock looks at an event it waits for


class ManualClock:
    """A clock whose time moves only when told (`advance`), or by itself with `autojump`."""

    def __init__(self, start: float = 0.0, autojump: float | None = None):
        self._now = start
        self._autojump = autojump  # [s] real
        self._cond = threading.Condition()
        self._deadlines: dict[int, float] = {}  # sleeping thread (its ident) -> its deadline

    def monotonic(self) -> float:
        return self._now

    def advance(self, seconds: float, settle: float = 5.0) -> None:
        """Move the time on by `seconds`; return once every thread it woke sleeps on this clock
        again or has ended, waiting at most `settle` real seconds for them."""
        if seconds < 0:
            raise ValueError("a clock never goes back")
        with self._cond:
            self._now += seconds
            woken = {t for t, d in self._deadlines.items() if d <= self._now}
            self._cond.notify_all()
            end = time.monotonic() + settle
            while time.monotonic() < end:
                alive = {t.ident for t in threading.enumerate()}
                if all(self._deadlines.get(t, self._now) > self._now or t not in alive for t in woken):
                    return
                self._cond.wait(POLL_S)

    def sleepers(self) -> int:
        """How many waits are on this clock now."""
        with self._cond:
            return len(self._deadlines)

    def until_sleeping(self, n: int = 1, timeout: float = 5.0) -> None:
        """Block (real time, bounded) until at least `n` waits are on this clock: the threads under test got there."""
        end = time.monotonic() + timeout
        with self._cond:
            while len(self._deadlines) < n:
                if time.monotonic() >= end:
                    raise TimeoutError(f"{len(self._deadlines)} of {n} sleepers on the clock after {timeout:g} s")
                self._cond.wait(POLL_S)

    def _wait(self, timeout: float, pause: Callable[[], bool]) -> bool:
        """Wait until `pause()` (which waits at most POLL_S real seconds) says what is waited for
        happened (True), or until this clock passes now + timeout (False)."""
        me = threading.get_ident()
        with self._cond:
            deadline = self._now + timeout
            self._deadlines[me] = deadline
            self._cond.notify_all()
        seen, idle_since = self._now, time.monotonic()
        try:
            while True:
                if self._now >= deadline:
                    return False
                if pause():
                    return True
                if self._now != seen:
                    seen, idle_since = self._now, time.monotonic()
                elif self._autojump is not None and time.monotonic() - idle_since >= self._autojump:
                    with self._cond:
                        self._now = max(self._now, min(self._deadlines.values()))
                        self._cond.notify_all()
        finally:
            with self._cond:
                del self._deadlines[me]
                self._cond.notify_all()

    def sleep(self, seconds: float) -> None:
        self._wait(seconds, _nap)

    def wait(self, event: threading.Event, timeout: float) -> bool:
        if event.is_set():
            return True
        return self._wait(timeout, lambda: event.wait(POLL_S))

    def wait_on(self, cond: threading.Condition, timeout: float) -> None:
        self._wait(timeout, lambda: cond.wait(POLL_S))  # the caller holds `cond`; a notify ends the wait


def _nap() -> bool:
    time.sleep(POLL_S)
    return False
