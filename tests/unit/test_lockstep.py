"""Lockstep links over the in-memory transport: schedules, lags, emulation, rejection, dead peers."""

from __future__ import annotations

import hashlib
import logging
import random
import threading
import time

import pytest

from arena.runtime.clock import MONOTONIC, ManualClock
from arena.runtime.links import LinkEmulator, LinkModel
from arena.runtime.lockstep import EVERY_TICK, Inbound, Outbound, Rejections, Schedule, Watchdog
from arena.runtime.transport import WAKE, MemoryBus, MemoryTransport
from arena.schemas.messages import Cmd, encode

KEY = "arena/t/robot/a/1/cmd"


@pytest.mark.parametrize(
    ("period", "phase", "k", "last", "due"),
    [(1, 0, 7, 7, True), (5, 0, 7, 5, False), (5, 1, 6, 6, True), (5, 1, 0, -1, False), (5, 4, 13, 9, False)],
)
def test_schedule(period, phase, k, last, due):
    s = Schedule(period, phase)
    assert s.last_at_or_before(k) == last
    assert s.due(k) is due
    assert s.first_after(s.last_at_or_before(k)) > k or s.last_at_or_before(k) == -1


class ScriptedLink(LinkEmulator):
    """A link whose delays are given in advance."""

    __slots__ = ("script",)

    def __init__(self, delays_ms):
        super().__init__(LinkModel(latency_ms=1.0), random.Random(0))
        self.script = iter(delays_ms)

    def decide(self, tick: int = -1):
        self.frames += 1
        return next(self.script)


def until(condition, timeout=5.0):
    """Wait (real time, bounded) until another thread has got where `condition` says."""
    end = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < end, "the other thread never got there"
        time.sleep(0.001)


class Harness:
    def __init__(self, model=None, schedule=EVERY_TICK, lag=1, timeout=5.0, emulator=None, clock=MONOTONIC):
        self.clock = clock
        self.bus = MemoryBus()
        self.rx = MemoryTransport(self.bus)
        self.tx = MemoryTransport(self.bus)
        self.rej = Rejections(logging.getLogger("test"))
        self.dead: dict[str, str] = {}
        self.gone: set[str] = set()
        self.wd = Watchdog(self.rx, timeout, clock=clock)
        self.inbound = Inbound(
            key=KEY,
            msg_type=Cmd,
            channel=self.rx.subscribe(KEY),
            schedule=schedule,
            lag=lag,
            link_class="sensor",
            sender="robot/a/1",
            emulator=emulator or LinkEmulator(model or LinkModel(), random.Random(1)),
            dt=0.02,
            rejections=self.rej,
            watchdog=self.wd,
            is_dead=self.gone.__contains__,
            on_dead=self.dead.__setitem__,
        )
        self.put = self.tx.publisher(KEY)

    def close(self):
        self.wd.stop()


@pytest.fixture
def h():
    harness = Harness()
    yield harness
    harness.close()


def test_frame_is_delivered_after_its_lag(h):
    h.put(encode(Cmd(tick=0, vx=1.0)))
    h.inbound.sync(1)
    assert h.inbound.take(0) == []
    assert [c.vx for c in h.inbound.take(1)] == [1.0]


def test_garbage_and_wrong_types_are_rejected_and_counted(h):
    h.put(b"\x00\xff garbage")
    h.put(encode(Cmd(tick=0)).replace(b"tick", b"tock"))  # required field missing
    h.put(b"\x81\xa4tick\xa3one")  # {"tick": "one"}
    h.put(encode(Cmd(tick=0)))
    h.inbound.sync(1)
    assert h.rej.by_reason["malformed"] == 3
    assert len(h.inbound.take(1)) == 1


def test_a_frame_over_the_size_limit_is_counted_too_large_unread_and_the_link_goes_on(h):
    from arena.schemas.keys import MAX_FRAME_BYTES

    at_limit = encode({"tick": 0, "vx": 1.0, "pad": "x" * (MAX_FRAME_BYTES - 30)})  # an unknown field pads it
    assert len(at_limit) <= MAX_FRAME_BYTES
    h.put(encode({"tick": 0, "vx": 9.0, "pad": "x" * MAX_FRAME_BYTES}))  # in sequence, but too long
    h.put(at_limit)
    h.put(encode(Cmd(tick=1, vx=2.0)))
    h.inbound.sync(2)
    assert h.rej.by_reason == {"too-large": 1}
    assert [c.vx for c in h.inbound.take(2)] == [1.0, 2.0]


def test_out_of_sequence_frames_are_rejected(h):
    h.put(encode(Cmd(tick=0)))
    h.put(encode(Cmd(tick=5)))  # skips ticks 1-4
    h.put(encode(Cmd(tick=0)))  # replay
    h.put(encode(Cmd(tick=1)))
    h.inbound.sync(2)
    assert h.rej.by_reason["out-of-sequence"] == 2
    assert h.inbound.last_seen == 1


def test_delay_rounds_up_to_the_next_tick():
    harness = Harness(model=LinkModel(latency_ms=25.0))  # 25 ms -> 2 ticks of 20 ms
    try:
        harness.put(encode(Cmd(tick=0)))
        harness.inbound.sync(1)
        assert harness.inbound.take(1) == []
        assert len(harness.inbound.take(2)) == 1
    finally:
        harness.close()


def test_dropped_frames_are_waited_for_then_discarded():
    harness = Harness(model=LinkModel(p_gb=1.0, p_bg=0.0, loss_bad=1.0))  # everything lost
    try:
        for k in range(3):
            harness.put(encode(Cmd(tick=k)))
        harness.inbound.sync(3)
        assert harness.inbound.take(10) == []
        assert harness.inbound.emulator.dropped == 3
    finally:
        harness.close()


def test_a_silent_sender_is_declared_dead_after_the_timeout():
    harness = Harness(timeout=0.3, clock=ManualClock())
    try:
        runner = threading.Thread(target=harness.inbound.sync, args=(1,))  # nobody sends tick 0
        runner.start()
        until(lambda: harness.wd._key is not None)  # the wait is armed, at time 0
        harness.clock.advance(0.2)
        assert not harness.inbound.dead and runner.is_alive(), "not before the timeout"
        harness.clock.advance(0.1)
        runner.join(5.0)
        assert not runner.is_alive() and "robot/a/1" in harness.dead and "silent for 0.3 s" in harness.dead["robot/a/1"]
        assert harness.inbound.dead
    finally:
        harness.close()


def test_a_vanished_sender_is_declared_dead_at_once(h):
    h.gone.add("robot/a/1")
    h.rx.wake(KEY)
    h.inbound.sync(1)
    assert "liveliness" in h.dead["robot/a/1"]


def test_outbound_digest_covers_key_and_payload():
    d1, d2 = hashlib.blake2b(), hashlib.blake2b()
    sent = []
    Outbound(KEY, "robot/a/1/cmd", sent.append, d1).send(Cmd(tick=0))
    Outbound(KEY, "robot/a/2/cmd", sent.append, d2).send(Cmd(tick=0))
    assert sent[0] == sent[1] and d1.digest() != d2.digest()


def test_a_late_old_frame_never_replaces_fresher_news():
    harness = Harness(emulator=ScriptedLink([65.0, 0.0]))  # tick 0 arrives 4 ticks late, tick 1 on time
    try:
        harness.put(encode(Cmd(tick=0, vx=0.0)))
        harness.put(encode(Cmd(tick=1, vx=1.0)))
        harness.inbound.sync(2)
        assert [c.tick for c in harness.inbound.take(2)] == [1]
        assert [c.tick for c in harness.inbound.take(4)] == [0]
        assert harness.inbound.latest.tick == 1
    finally:
        harness.close()


# ------------------------------------------------------------------ Reactor
def _two_link_loop(a, b, log, last=6):
    """A lockstep loop over two links, as a process writes it (runtime/node.py)."""
    for k in range(last + 1):
        yield a, k
        yield b, k
        log.append((k, [m.tick for m in a.take(k)], [m.tick for m in b.take(k)]))


def _frames(ticks):
    return [encode(Cmd(tick=t)) for t in ticks]


def _two_harnesses(**kw):
    return Harness(**kw), Harness(schedule=Schedule(2, 0), **kw)


def _fed(a, b) -> None:
    """Every frame of the two-link loop's seven ticks queued on its harness (b's every other tick)."""
    for raw in _frames(range(7)):
        a.put(raw)
    for raw in _frames(range(0, 7, 2)):
        b.put(raw)


def _pulled() -> list:
    """The steps of the two-link loop pulled over `_fed` harnesses: what every other driver must take."""
    from arena.runtime.drivers import pull

    pulled: list = []
    a, b = _two_harnesses()
    _fed(a, b)
    pull(_two_link_loop(a.inbound, b.inbound, pulled))
    for harness in (a, b):
        harness.close()
    return pulled


def test_the_reactor_runs_a_loop_exactly_as_pulling_does():
    """Same frames, any arrival order between links: the same steps, whoever drives."""
    from arena.runtime.drivers import Reactor

    pulled = _pulled()
    reacted: list = []
    a2, b2 = _two_harnesses()
    reactor = Reactor(timeout=5.0)
    done = threading.Thread(target=reactor.run, args=(_two_link_loop(a2.inbound, b2.inbound, reacted),))
    done.start()
    # Frames come from another thread, interleaved differently from the pull run.
    for t in range(7):
        reactor.on_frame(a2.inbound, _frames([t])[0])
        if t % 2 == 0:
            reactor.on_frame(b2.inbound, _frames([t])[0])
    done.join(5.0)
    assert not done.is_alive() and reactor.error is None
    assert reacted == pulled and len(reacted) == 7
    for harness in (a2, b2):
        harness.close()


def test_every_driver_runs_a_loop_through_the_one_advance_and_flushes_before_a_wait_not_paired():
    """`Pull`, `Reactor` and the cooperative `Task` take the same steps; each calls `before_wait`
    only where the loop is about to wait on a link that is not ready and not `paired`."""
    from arena.runtime import coop
    from arena.runtime.drivers import Pull, Reactor

    runs = {}
    for name in ("pull", "reactor", "coop"):
        log: list = []
        flushed: list = []
        a, b = _two_harnesses()
        b.inbound.paired = True  # never flushed for
        steps = _two_link_loop(a.inbound, b.inbound, log)
        flush = lambda log=log, flushed=flushed: flushed.append(len(log))
        if name == "pull":
            _fed(a, b)
            driver = Pull(a.rx, 5.0)
            assert list(driver.drive(steps, flush)) == [], "a blocking driver yields nothing"
            driver.close()
        elif name == "reactor":
            reactor = Reactor(timeout=5.0)
            runner = threading.Thread(target=lambda r=reactor, s=steps, f=flush: list(r.drive(s, f)))
            runner.start()
            for t in range(7):
                reactor.on_frame(a.inbound, _frames([t])[0])
                if t % 2 == 0:
                    reactor.on_frame(b.inbound, _frames([t])[0])
            runner.join(5.0)
            assert not runner.is_alive() and reactor.error is None
        else:
            bus = coop.CoopBus()
            a.inbound.channel = bus.subscribe(None, "arena/t/a")
            b.inbound.channel = bus.subscribe(None, "arena/t/b")
            task = coop.Task("n")
            task.steps = task.drive(steps, flush)
            coop._advance(task)
            assert task.waiting == (a.inbound, 1) and flushed == [1], "parked at the first missing frame, flushed"
            for t in range(7):
                bus.deliver("arena/t/a", _frames([t])[0])
                if t % 2 == 0:
                    bus.deliver("arena/t/b", _frames([t])[0])
            assert coop.drive(bus, [task]) == [] and task.done
        runs[name] = (log, flushed)
        for harness in (a, b):
            harness.close()
    assert runs["pull"][0] == runs["reactor"][0] == runs["coop"][0] and len(runs["pull"][0]) == 7
    # Pulling, each frame is taken in by the `sync` after the flush: one flush per wait on `a`,
    # none for `b` (paired). The others flush only where the frame was not there yet.
    assert runs["pull"][1] == [1, 2, 3, 4, 5, 6]
    assert runs["coop"][1] == [1], "the coop driver takes in what arrived before it parks"
    assert set(runs["reactor"][1]) <= set(runs["pull"][1])


def test_the_reactor_stops_at_the_first_missing_frame_and_goes_on_when_it_comes():
    from arena.runtime.drivers import Reactor

    log: list = []
    a, b = _two_harnesses()
    reactor = Reactor(timeout=5.0)
    runner = threading.Thread(target=reactor.run, args=(_two_link_loop(a.inbound, b.inbound, log, last=3),))
    runner.start()
    for t in range(3):
        reactor.on_frame(a.inbound, _frames([t])[0])
    reactor.on_frame(b.inbound, _frames([0])[0])
    until(lambda: reactor._waiting is not None and len(log) == 3)
    assert [k for k, _, _ in log] == [0, 1, 2], "tick 3 needs b's frame sent at 2 (lag 1, period 2)"
    assert not reactor.done.is_set()
    reactor.on_frame(b.inbound, _frames([2])[0])
    runner.join(5.0)
    assert [k for k, _, _ in log] == [0, 1, 2, 3] and reactor.done.is_set()
    a.close()
    b.close()


def test_the_reactor_gives_up_on_a_silent_link_and_on_a_vanished_sender():
    from arena.runtime.drivers import Reactor

    a, b = _two_harnesses()
    log: list = []
    clock = ManualClock(autojump=0.005)  # the reactor's own looks move the time on
    reactor = Reactor(timeout=0.3, clock=clock)
    reactor.on_frame(b.inbound, _frames([0])[0])
    t0 = time.monotonic()
    reactor.run(_two_link_loop(a.inbound, b.inbound, log, last=0))  # a never sends tick... lag 1 needs nothing at 0
    assert log == [(0, [], [])]
    clock2 = ManualClock(autojump=0.005)
    reactor2 = Reactor(timeout=0.3, clock=clock2)
    a2, b2 = _two_harnesses()
    reactor2.run(_two_link_loop(a2.inbound, b2.inbound, [], last=3))  # nobody sends anything
    assert a2.inbound.dead and b2.inbound.dead and "silent" in a2.dead["robot/a/1"]
    assert 0.6 - 1e-9 <= clock2.monotonic() < 0.8, "each link given up a full timeout after its own wait began"
    assert time.monotonic() - t0 < 5.0

    # A vanished sender: its wake-up ends the wait at once, a stale one does not.
    a3, b3 = _two_harnesses()
    reactor3 = Reactor(timeout=30.0)
    runner = threading.Thread(target=reactor3.run, args=(_two_link_loop(a3.inbound, b3.inbound, [], last=2),))
    runner.start()
    until(lambda: reactor3._waiting is not None)
    reactor3.on_frame(a3.inbound, WAKE)  # stale: the sender is still there (looked at before on_frame returns)
    assert not a3.inbound.dead
    a3.gone.add("robot/a/1")
    b3.gone.add("robot/a/1")
    reactor3.on_frame(a3.inbound, WAKE)
    reactor3.on_frame(b3.inbound, WAKE)
    runner.join(5.0)
    assert not runner.is_alive() and "liveliness" in a3.dead["robot/a/1"]
    for harness in (a, b, a2, b2, a3, b3):
        harness.close()


def test_the_reactor_announces_a_long_wait_and_waits_on_while_its_sender_waits_upstream():
    """Issue 20: only the receiver of the frame that is owed gives up; a sender that waits for its own
    upstream at a tick not past the missing frame owes nothing yet."""
    from arena.runtime.drivers import Reactor

    h = Harness()
    clock = ManualClock()
    announced: list = []
    upstream = {"robot/a/1": 0}  # the tick the sender announces it waits before; None: not waiting
    asked: list = []

    def upstream_waited(sender, missing):
        asked.append((sender, missing))
        at = upstream[sender]
        return clock.monotonic() if at is not None and at <= missing else None

    def loop():
        for k in range(3):
            yield h.inbound, k

    reactor = Reactor(timeout=0.3, announce=announced.append, upstream_waited=upstream_waited, clock=clock)
    runner = threading.Thread(target=reactor.run, args=(loop(),))
    runner.start()
    clock.until_sleeping(1)  # its main thread looks every 0.1 s of the clock
    for _ in range(10):  # three timeouts: the sender waits before tick 0, frame 0 is missing, so we wait on
        clock.advance(0.1)
    assert not h.inbound.dead and runner.is_alive()
    assert announced == [1], "the wait before acting at tick 1 is announced, and stays so while it goes on"
    assert asked and set(asked) == {("robot/a/1", 0)}
    upstream["robot/a/1"] = 5  # it went past tick 0 without sending it: it owes the frame
    clock.advance(0.1)
    runner.join(5.0)
    assert not runner.is_alive() and h.inbound.dead and "silent" in h.dead["robot/a/1"]
    assert announced[-1] is None, "taken back when the loop ends"
    h.close()


def test_a_sender_owes_a_frame_only_since_it_stopped_waiting_upstream():
    """Issue 20, the co-blamed engine: a sender stalled upstream moves on from one stalled wait to the
    next (the engine got robot a/0's cmd, then waited for a/1's) and announces the new one only
    `announce_after` later. A receiver whose own timeout fell in that gap gave up on it. Its silence
    is counted from when it took its last announcement back, and the receiver's own wait stays
    announced meanwhile (it used to take its token back for `announce_after` whenever it waited on)."""
    from arena.runtime.drivers import Reactor

    h = Harness()
    clock = ManualClock()
    timeout = 0.8  # announce_after 0.2: a token taken back would show at the next look, 0.1 s later
    announced: list = []
    took_back: dict = {"at": None}  # when the sender took back its announced wait; None: never announced one

    def upstream_waited(sender, missing):
        return took_back["at"]

    def loop():
        yield h.inbound, 1

    reactor = Reactor(timeout=timeout, announce=announced.append, upstream_waited=upstream_waited, clock=clock)
    runner = threading.Thread(target=reactor.run, args=(loop(),))
    t0 = clock.monotonic()
    runner.start()
    clock.until_sleeping(1)
    for _ in range(6):
        clock.advance(0.1)
    clock.advance(0.05)
    took_back["at"] = clock.monotonic()  # just before our timeout: it stopped waiting upstream only now
    for _ in range(5):  # our own wait is past the timeout, the sender's debt is not
        clock.advance(0.1)
    assert not h.inbound.dead and runner.is_alive()
    for _ in range(20):  # nothing comes: it is silent a full timeout after it took its announcement back
        if not runner.is_alive():
            break
        clock.advance(0.1)
    runner.join(5.0)
    assert not runner.is_alive() and h.inbound.dead and "silent" in h.dead["robot/a/1"]
    assert (timeout - 0.15) + timeout - 1e-9 <= clock.monotonic() - t0 < (timeout - 0.15) + timeout + 0.2
    assert announced == [1, None], "announced once, until it gave up"
    h.close()

    # A sender that took its announcement back before we started to wait owes the frame all along.
    h2 = Harness()
    clock2 = ManualClock(autojump=0.005)
    took_back["at"] = clock2.monotonic() - 10.0

    def loop2():
        yield h2.inbound, 1

    t1 = clock2.monotonic()
    Reactor(timeout=0.3, upstream_waited=upstream_waited, clock=clock2).run(loop2())
    assert h2.inbound.dead and 0.3 - 1e-9 <= clock2.monotonic() - t1 < 0.5
    h2.close()


def test_a_node_remembers_when_a_peer_stopped_waiting_before_each_tick():
    """`WaitBoard.upstream_waited`, fed by the peers' `waiting/<process>/<tick>` tokens."""
    from arena.runtime.drivers import WaitBoard
    from arena.schemas.keys import Keys

    class Tokens(MemoryTransport):
        def watch_alive(self, key_expr, on_change):
            self.watched = key_expr

    clock = ManualClock()
    board = WaitBoard(Tokens(MemoryBus()), Keys("m"), "robot/a/0", clock)
    assert board._transport.watched == Keys("m").waiting_all()
    key = "arena/m/waiting/{}/{}".format
    assert board.upstream_waited("engine", 4) is None, "never announced a wait"
    board.on_waiting(key("engine", 3), True)
    clock.advance(1.0)
    assert board.upstream_waited("engine", 4) == clock.monotonic() == 1.0, "waits now"
    assert board.upstream_waited("engine", 2) is None, "before acting at 3, it owes frame 2"
    clock.advance(1.0)
    board.on_waiting(key("engine", 3), False)
    gone = board.upstream_waited("engine", 4)
    assert gone == 2.0, "until the moment it took its token back"
    clock.advance(0.01)
    assert board.upstream_waited("engine", 4) == gone
    board.on_waiting(key("engine", 7), True)
    assert board.upstream_waited("engine", 4) == gone, "a wait past the missing frame is no excuse"
    board.on_waiting(key("robot/a/1", 2), True)
    assert board.upstream_waited("robot/a/1", 2) is not None and board.upstream_waited("engine", 3) == gone


def test_an_error_in_a_reactive_loop_is_raised_on_the_main_thread():
    from arena.runtime.drivers import Reactor

    h = Harness()

    def broken():
        yield h.inbound, 0
        raise ValueError("boom")

    with pytest.raises(ValueError, match="boom"):
        Reactor(timeout=1.0).run(broken())
    h.close()


def test_the_counters_count_the_frames_waited_for_not_those_racing_the_end():
    """links.sensor.sent was 72012, 72004, 72006 in runs of one seed: frames that landed after the
    receiver's last wait were counted or not depending on how fast its summary was taken."""
    from arena.runtime.drivers import pull

    harness = Harness(emulator=ScriptedLink([0.0, None, 30.0, 0.0, None, 0.0, 0.0]))
    try:
        ib = harness.inbound

        def loop():
            for k in range(1, 5):  # waits for ticks 0..3 (lag 1)
                yield ib, k

        for k in range(4):
            harness.put(encode(Cmd(tick=k)))
        pull(loop())
        frames, dropped, delays = ib.counted()
        assert (frames, dropped) == (4, 1)
        for k in range(4, 7):  # in flight at the end: taken in by the transport's callback, or not
            harness.put(encode(Cmd(tick=k)))
        ib.sync(7)
        assert ib.emulator.frames == 7 and ib.counted() == (frames, dropped, delays), "the late ones do not count"
    finally:
        harness.close()


def test_in_real_time_an_ideal_link_counts_every_frame_it_takes_in(h):
    """Real time reports the link emulation's own count (`counted`); an ideal link's frames are
    counted by the receiver, not by `decide` (in lockstep nobody reads that count)."""
    h.inbound.strict = False
    for k in (0, 1, 3, 2, 4):  # tick 2 after 3: refused, not counted
        h.put(encode(Cmd(tick=k)))
    h.inbound.poll(5)
    assert h.inbound.emulator.on_time and h.inbound.counted() == (4, 0, [])


def test_a_genuine_frame_after_forged_ones_ahead_is_a_conflict_whatever_its_tick(h, caplog):
    """A stranger without keys (a process started by hand, no MACs to check) puts ticks 0..4
    ahead of the genuine sender: they take the slots, and each genuine frame that follows is
    a conflict on this key, not `out-of-sequence` (only tick == last seen counted before);
    "possible spoofing on KEY" is logged once, and the key is queued for its announcement."""
    for t in range(5):
        h.put(encode(Cmd(tick=t, vx=-5.0)))
    h.inbound.sync(4 + h.inbound.lag)
    caplog.set_level(logging.WARNING)
    for t in range(5):
        h.put(encode(Cmd(tick=t, vx=1.0)))  # the genuine frames, for ticks already taken
    h.put(encode(Cmd(tick=3, vx=-5.0)))  # a repeat of an accepted frame: out of sequence, no conflict
    h.put(encode(Cmd(tick=5, vx=1.0)))
    h.inbound.sync(5 + h.inbound.lag)
    assert h.rej.conflicts == {KEY: 5}, h.rej.by_reason
    assert h.rej.by_reason["out-of-sequence"] == 1
    assert [r.getMessage() for r in caplog.records].count(f"possible spoofing on {KEY}") == 1
    assert h.rej.spoofed_new == [KEY]


def test_a_forged_frame_is_counted_per_key_and_announced_once():
    rej = Rejections(logging.getLogger("test"))
    for _ in range(3):
        rej.forged(KEY, "robot/a/1")
    rej.forged("arena/t/referee", "referee")
    assert rej.forged_by_key == {KEY: 3, "arena/t/referee": 1}
    assert rej.by_reason == {"forged": 4} and rej.conflicts == {}
    assert rej.spoofed_new == [KEY, "arena/t/referee"]


@pytest.mark.parametrize(("period", "phase", "lag"), [(1, 0, 0), (1, 0, 1), (1, 0, 3), (5, 0, 1), (5, 4, 1), (5, 2, 0)])
def test_ready_is_every_frame_due_by_k_minus_lag_in_or_a_dead_sender(period, phase, lag):
    """`ready(k)` as kept per frame (`ready_below`) says what its definition says, at every k, as frames come."""
    schedule = Schedule(period, phase)
    h = Harness(schedule=schedule, lag=lag)
    ib = h.inbound

    def defined(k):
        return ib.dead or ib.last_seen >= schedule.last_at_or_before(k - lag)

    for t in [-1, *schedule.ticks(30)]:
        if t >= 0:
            h.put(encode(Cmd(tick=t)))
            ib.drain()
            assert ib.last_seen == t
        assert [ib.ready(k) for k in range(40)] == [defined(k) for k in range(40)]
    ib.give_up("test")
    assert all(ib.ready(k) for k in range(10_000))
    h.put(encode(Cmd(tick=schedule.first_after(30))))
    ib.drain()
    assert ib.ready(10_000), "a dead sender's late frame makes nobody wait for it again"
    h.close()
