"""One clock for a run (runtime/clock.py): the engine's real-time loop, the summary's delivery
and the recorder wait on the `Clock` they are given (the live pacer too: tests/unit/test_pace.py),
so a test moves a `ManualClock` on instead of sleeping and says which instant it checks."""

from __future__ import annotations

import threading
import time

import pytest

from arena.config import MatchConfig, ProcessId
from arena.runtime.clock import ManualClock
from arena.runtime.coop import Task
from arena.runtime.transport import MemoryBus, MemoryTransport
from arena.schemas.keys import Keys


def test_the_real_time_engine_keeps_pace_with_its_clock():
    from arena.processes.engine import EngineNode

    clock = ManualClock(autojump=0.0)  # every sleep ends at its deadline at once
    cfg = MatchConfig(realtime=True, half_time=0.5)
    # A driver without a watchdog thread: the loop is the one sleeper on the clock.
    node = EngineNode(ProcessId("engine"), cfg, MemoryTransport(MemoryBus()), Keys("t"), driver=Task("e"), clock=clock)
    t0 = time.monotonic()
    node.loop_realtime()
    assert node.last_tick == cfg.total_ticks
    assert clock.monotonic() == pytest.approx(cfg.total_ticks * cfg.timing.dt), "one dt of its clock per tick"
    assert time.monotonic() - t0 < cfg.total_ticks * cfg.timing.dt, "not the wall's"


def _robot(bus: MemoryBus, clock: ManualClock):
    from arena.processes.robot import RobotNode

    pid = ProcessId("robot", "a", 0)
    return RobotNode(pid, MatchConfig(robots=1), MemoryTransport(bus), Keys("t"), driver=Task(str(pid)), clock=clock)


def test_a_summary_is_put_again_until_acknowledged_or_the_bound_of_its_clock():
    bus, clock = MemoryBus(), ManualClock()
    node = _robot(bus, clock)
    node._collector = True  # a collector is there (arena match): it acknowledges, or the bound ends it
    seen = MemoryTransport(bus).subscribe(node.keys.summary(node.name))
    t = threading.Thread(target=node.deliver_summary, args=(b"summary", 5.0), daemon=True)
    t.start()
    for _ in range(19):  # one put every 0.25 s of its clock, for 5 s
        clock.until_sleeping()
        clock.advance(0.25)
    assert t.is_alive()
    clock.advance(0.25)
    t.join(5.0)
    assert not t.is_alive()
    puts = 0
    while seen.try_recv() is not None:
        puts += 1
    assert puts == 20

    node = _robot(bus, clock)
    node._collector = True
    t = threading.Thread(target=node.deliver_summary, args=(b"summary", 5.0), daemon=True)
    t.start()
    clock.until_sleeping()
    MemoryTransport(bus).publisher(node.keys.ack(node.name))(b"ok")
    clock.advance(0.005)
    t.join(5.0)
    assert not t.is_alive(), "an acknowledgement ends it at once"


def test_the_recorder_closes_a_recording_whose_taps_fell_silent_for_wait_timeout(tmp_path):
    from arena.processes.recorder import POLL_S, RecorderNode

    clock = ManualClock()
    cfg = MatchConfig(tap=True, half_time=1.0)
    path = tmp_path / "silent.mcap"
    node = RecorderNode(
        ProcessId("recorder"), cfg, MemoryTransport(MemoryBus()), Keys("t"), path=str(path), clock=clock
    )
    t = threading.Thread(target=node.observe, daemon=True)  # not the main thread: no signal handlers, no nice
    t.start()
    clock.until_sleeping()
    clock.advance(cfg.timing.wait_timeout)
    assert t.is_alive(), "silent for exactly wait_timeout: still waiting"
    clock.advance(POLL_S)
    t.join(10.0)
    assert not t.is_alive() and path.stat().st_size > 0
