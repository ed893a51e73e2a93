"""The injectable clock (runtime/clock.py): a ManualClock moves only when told, and what it wakes is done
when `advance` returns; the start barrier is bounded in the clock's time."""

from __future__ import annotations

import threading
import time

import pytest

from arena.runtime.clock import MONOTONIC, ManualClock


def test_advance_wakes_each_sleeper_whose_deadline_passed_and_returns_once_it_sleeps_again():
    clock = ManualClock()
    woke: list[float] = []
    stop = threading.Event()

    def every_tenth():  # a loop like the watchdog's or the Reactor's
        while not clock.wait(stop, 0.1):
            woke.append(clock.monotonic())

    t = threading.Thread(target=every_tenth)
    t.start()
    clock.until_sleeping(1)
    clock.advance(0.05)
    assert woke == [], "not before its deadline"
    clock.advance(0.05)
    assert woke == [pytest.approx(0.1)], "done by the time advance returns"
    clock.advance(0.35)
    assert woke == [pytest.approx(0.1), pytest.approx(0.45)], "one wake per advance, at the time it moved to"
    stop.set()
    t.join(5.0)
    assert not t.is_alive() and clock.sleepers() == 0
    with pytest.raises(ValueError, match="never goes back"):
        clock.advance(-1.0)


def test_an_event_or_a_notify_ends_a_wait_without_the_time_moving():
    clock = ManualClock(start=5.0)
    ev = threading.Event()
    threading.Timer(0.02, ev.set).start()
    assert clock.wait(ev, 3600.0) is True and clock.monotonic() == 5.0
    cond = threading.Condition()

    def notify():
        with cond:
            cond.notify_all()

    t0 = time.monotonic()
    with cond:  # the timer starts with `cond` held: its notify cannot come before the wait (it hung under load)
        threading.Timer(0.02, notify).start()
        clock.wait_on(cond, 3600.0)
    assert time.monotonic() - t0 < 5.0 and clock.monotonic() == 5.0


def test_autojump_moves_the_time_to_the_next_deadline_when_nothing_happens():
    clock = ManualClock(autojump=0.005)
    t0 = time.monotonic()
    clock.sleep(60.0)
    assert clock.monotonic() == 60.0 and time.monotonic() - t0 < 5.0
    assert clock.wait(threading.Event(), 30.0) is False and clock.monotonic() == 90.0


def test_the_real_clock_is_time_monotonic():
    before = time.monotonic()
    assert before <= MONOTONIC.monotonic() <= time.monotonic()
    assert MONOTONIC.wait(threading.Event(), 0.0) is False


def test_the_start_barrier_gives_up_after_startup_timeout_of_its_clock_and_says_who_is_missing():
    from arena.config import MatchConfig, ProcessId
    from arena.processes.robot import RobotNode
    from arena.runtime.coop import Task
    from arena.runtime.node import StartupError
    from arena.runtime.transport import MemoryBus, MemoryTransport
    from arena.schemas.keys import Keys

    clock = ManualClock(autojump=0.002)
    cfg = MatchConfig(robots=1)
    pid = ProcessId("robot", "a", 0)
    # A driver without a watchdog thread: the barrier is the one sleeper on the clock.
    node = RobotNode(pid, cfg, MemoryTransport(MemoryBus()), Keys("t"), driver=Task(str(pid)), clock=clock)
    told: list[tuple[float, list[str]]] = []
    node.on_waiting = lambda missing: told.append((clock.monotonic(), missing))
    t0 = time.monotonic()
    with pytest.raises(StartupError, match=r"gave up after 30 s waiting for: basestation/a, .*engine"):
        node.barrier()
    assert clock.monotonic() == pytest.approx(cfg.timing.startup_timeout), "at the bound, not before"
    assert time.monotonic() - t0 < 10.0, "30 s of its clock, not of the wall"
    assert len(told) == 1 and 1.0 < told[0][0] <= 1.5 and "engine" in told[0][1], "the missing, once, after 1 s"
