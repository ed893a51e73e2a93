"""The cooperative driver (runtime/coop.py): one thread, and a node that stops is detected, never waited on."""

from __future__ import annotations

import logging
import threading

import pytest

from arena.config import MatchConfig
from arena.match import inprocess
from arena.processes import node_class
from arena.processes.robot import RobotNode


class QuitsAtTick20(RobotNode):
    """A robot whose loop ends early: its peers would wait for its frames for ever."""

    def lockstep(self):
        for step in super().lockstep():
            if self.last_tick >= 20 and self.pid.team == "b" and self.pid.robot == 1:
                return
            yield step


def test_a_node_that_stops_sending_is_a_detected_deadlock_and_the_match_goes_on(monkeypatch):
    monkeypatch.setattr(inprocess, "node_class", lambda kind: QuitsAtTick20 if kind == "robot" else node_class(kind))
    threads = threading.active_count()
    result = inprocess.play_match(MatchConfig(seed=4, half_time=2.0)).to_dict()
    assert threading.active_count() == threads, "no thread was started"
    assert result["ticks"] == 200, "the match was played to its end"
    assert result["deadlocks"] and "robot/b/1" in result["deadlocks"][0]
    assert "robot/b/1" in result["dead"]


def test_a_process_a_scenario_kills_is_dead_quietly_not_a_deadlock(caplog):
    """`arena scenario run` of the rule library printed 'deadlock: every unfinished node waits'
    and 'treating robot/a/1 as dead' for the kill step it asked for; --engine processes printed nothing."""
    from arena.config import ScenarioParams
    from arena.schemas.messages import KillProcess, RefereeOverride, Step

    steps = (Step(at=0, actions=[RefereeOverride(command="START")]), Step(at=50, actions=[KillProcess("robot/b/1")]))
    cfg = MatchConfig(seed=4, half_time=2.0, scenario=ScenarioParams(ticks=100, steps=steps))
    r = inprocess.play_match(cfg).to_dict()
    assert r["ticks"] == 100 and "robot/b/1" in r["dead"] and "b/1" in r["parked"]
    assert r["deadlocks"] == []
    loud = [rec.getMessage() for rec in caplog.records if rec.levelno >= logging.WARNING]
    assert not any("robot/b/1" in m or "b/1 is dead" in m or "deadlock" in m for m in loud), loud


def test_a_clean_match_has_no_deadlock_and_one_pid():
    r = inprocess.play_match(MatchConfig(seed=4, half_time=1.0)).to_dict()
    assert r["deadlocks"] == [] and r["dead"] == [] and r["engine"] == "inprocess"
    assert len({p["pid"] for p in r["processes"]}) == 1


def test_a_node_that_raises_ends_the_match_with_its_name(monkeypatch):
    class Broken(RobotNode):
        def act(self, k: int) -> None:
            if k == 7:
                raise ZeroDivisionError("a strategy divided by zero")
            super().act(k)

    monkeypatch.setattr(inprocess, "node_class", lambda kind: Broken if kind == "robot" else node_class(kind))
    # Every robot breaks at tick 7: whichever the scheduler runs first names itself.
    with pytest.raises(inprocess.InprocessError, match=r"robot/[ab]/[0-2] failed: ZeroDivisionError"):
        inprocess.play_match(MatchConfig(seed=4, half_time=1.0))


def test_observers_are_not_nodes_and_a_node_takes_its_driver():
    """The recorder and viewer are `Observer`s (no lockstep, no driver); a `Node` is driven by what it is given."""
    import gc

    from arena.config import ProcessId
    from arena.match import run
    from arena.processes import OBSERVERS
    from arena.runtime.coop import CoopBus, Task
    from arena.runtime.drivers import Pull, Reactor
    from arena.runtime.node import Node, Observer
    from arena.runtime.transport import MemoryBus, MemoryTransport
    from arena.schemas.keys import Keys

    for kind in OBSERVERS:
        cls = node_class(kind)
        assert issubclass(cls, Observer) and not issubclass(cls, Node) and not hasattr(cls, "lockstep")
    cfg = MatchConfig(seed=4, half_time=1.0)
    pid = ProcessId("robot", "a", 0)
    pulled = RobotNode(pid, cfg, MemoryTransport(MemoryBus()), Keys("t"))
    assert isinstance(pulled.driver, Pull) and pulled.inbound[0].channel is not None
    pulled.close()
    coop = RobotNode(pid, cfg, MemoryTransport(CoopBus()), Keys("t"), driver=Task(str(pid)))
    with pytest.raises(RuntimeError, match="played by its scheduler"):
        coop.play()  # its loop waits at once on a frame only a scheduler can bring
    gc.unfreeze()

    class Tokens(MemoryTransport):
        def watch_alive(self, key_expr, on_change):
            self.watched = key_expr

    tr = Tokens(MemoryBus())
    assert isinstance(run.driver(pid, cfg, tr, Keys("t"))["driver"], Reactor) and tr.watched == Keys("t").waiting_all()
    realtime = run.driver(pid, cfg.replace(realtime=True), tr, Keys("t"))["driver"]
    assert isinstance(realtime, Pull)
    realtime.close()
    assert run.driver(ProcessId("recorder"), cfg, tr, Keys("t")) == {}


def test_a_cooperative_link_takes_a_frame_in_as_it_is_put_and_wakes_its_task_only_once_ready():
    """`CoopLink`: no queue to drain at the next wait, and no resume for a frame that does not make
    the link ready for the tick its task waits on; the loop sees what a pulling driver sees."""
    from arena.runtime import coop
    from tests.unit.test_lockstep import _frames, _pulled, _two_harnesses, _two_link_loop

    pulled = _pulled()

    log: list = []
    a2, b2 = _two_harnesses()
    bus = coop.CoopBus()
    for h, key in ((a2, "arena/t/a"), (b2, "arena/t/b")):
        h.inbound.key = key
        coop.connect(h.inbound, coop.MemoryTransport(bus), None, None)
    task = coop.Task("n")
    task.steps = task.drive(_two_link_loop(a2.inbound, b2.inbound, log), None)
    coop._advance(task)
    assert task.waiting == (a2.inbound, 1) and a2.inbound.channel.waiter is task
    bus.deliver("arena/t/b", _frames([0])[0])
    assert b2.inbound.last_seen == 0, "taken in as it was put"
    assert not bus.runnable, "a frame on another link wakes nobody"
    bus.deliver("arena/t/a", _frames([0])[0])
    assert list(bus.runnable) == [task] and a2.inbound.channel.waiter is None, "ready for tick 1: woken"
    for t in range(1, 7):
        bus.deliver("arena/t/a", _frames([t])[0])
        if t % 2 == 0:
            bus.deliver("arena/t/b", _frames([t])[0])
    assert a2.inbound.channel.try_recv() is None, "nothing queued"
    assert coop.drive(bus, [task]) == [] and task.done
    assert log == pulled and len(log) == 7
    for h in (a2, b2):
        h.close()


def test_a_straightened_publisher_puts_into_its_one_target_and_a_later_subscriber_still_gets_every_frame():
    """`CoopBus.straighten`: a key with one target is put straight into it; a subscriber that comes
    later puts the publisher back on its putter (so it gets every frame after), and a muted key stays muted."""
    import hashlib

    from arena.runtime.coop import CoopBus
    from arena.runtime.lockstep import Latest, Outbound
    from arena.schemas.messages import Cmd, encode

    bus = CoopBus()
    first = bus.subscribe("a", "arena/t/x")
    plain = Outbound("arena/t/x", "x", bus.putter("arena/t/x"), hashlib.blake2b())
    served = Outbound("arena/t/x", "x", bus.putter("arena/t/x"), hashlib.blake2b())
    latest = Latest()
    served.put_through(latest.wrap)
    muted = Outbound("arena/t/x", "x", bus.putter("arena/t/x"), hashlib.blake2b())
    bus.straighten([plain, served, muted])
    assert plain._put == first.put and latest._put == first.put, "straight into the one target"
    muted.mute()
    for ob in (plain, served, muted):
        ob.send(Cmd(tick=0))
    later = bus.subscribe("b", "arena/t/**")
    for ob in (plain, served, muted):
        ob.send(Cmd(tick=1))
    got = [first.try_recv() for _ in range(6)]
    assert got[:2] == [encode(Cmd(tick=0))] * 2 and got[2:4] == [encode(Cmd(tick=1))] * 2 and got[4:] == [None] * 2
    assert [later.try_recv() for _ in range(3)] == [encode(Cmd(tick=1))] * 2 + [None], "the later subscriber too"
    assert latest.get() == encode(Cmd(tick=1))


def test_a_cooperative_link_replaces_a_non_finite_frame_whether_its_own_process_or_another_put_it():
    """`CoopLink.own` (a publisher of this process, msgspec: float64 only) scans for two pairs,
    `put` (anything else, e.g. a replay's recorded frames) for all four (`validate.suspect`)."""
    import hashlib
    import math
    import struct

    from arena.runtime import coop
    from arena.runtime.lockstep import Outbound
    from arena.schemas.messages import Cmd, encode
    from tests.unit.test_lockstep import KEY, Harness

    h = Harness()
    bus = coop.CoopBus()
    coop.connect(h.inbound, coop.MemoryTransport(bus), None, None)
    ob = Outbound(KEY, "robot/a/1/cmd", coop.MemoryTransport(bus).publisher(KEY), hashlib.blake2b())
    bus.straighten([ob])
    assert ob._put == h.inbound.channel.own()
    for vx in (1.0, math.nan, -math.inf, math.inf, 2.0):
        ob.send(Cmd(tick=h.inbound.last_seen + 1, vx=vx))
    float32_nan = encode(Cmd(tick=5, vx=1.5)).replace(struct.pack(">Bd", 0xCB, 1.5), b"\xca\x7f\xc0\x00\x00")
    assert h.inbound._decode(float32_nan).vx != h.inbound._decode(float32_nan).vx  # NaN, as a float32
    bus.deliver(KEY, float32_nan)
    bus.deliver(KEY, encode(Cmd(tick=6, vx=3.0)))
    h.close()
    assert h.rej.by_reason == {"invalid": 4}
    assert [c.vx for c in h.inbound.take(7)] == [1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 3.0]
