"""The live pacer (runtime/pace.py): it only ever delays a tick; and the CLI's --live/--pace checks."""

from __future__ import annotations

import subprocess
import sys
import threading

import pytest

from arena.config import ConfigError, MatchConfig
from arena.runtime.clock import ManualClock
from arena.runtime.pace import BEHIND_S, Pacer, WireGate
from arena.schemas.messages import Control, encode
from tests.integration.helpers import arena_in_process


def test_unpaced_and_unpaused_every_tick_is_ready():
    p = Pacer(0.02, 0.0)
    assert all(p.ready(k) for k in range(1000))


def test_pause_holds_the_next_tick_and_step_lets_exactly_n_through():
    p = Pacer(0.02, 0.0)
    assert p.ready(0) and p.ready(1)
    p.control(Control(tick=1, seq=1, paused=True))
    assert not p.ready(2)
    p.control(Control(tick=1, seq=2, paused=True, step=3))
    assert [p.ready(k) for k in (2, 3, 4)] == [True, True, True]
    assert not p.ready(5)
    p.control(Control(tick=4, seq=2, paused=False))  # a repeated seq is ignored
    assert not p.ready(5)
    p.control(Control(tick=4, seq=3, paused=False))
    assert p.ready(5)


def test_the_wire_gate_passes_every_nth_frame_and_the_held_one_when_the_pacer_holds():
    wire: list[bytes] = []
    gate = WireGate(5).wrap(wire.append)
    p = Pacer(0.02, 0.0)
    p.on_hold = gate.flush
    for k in range(12):
        assert p.ready(k)
        gate(b"%d" % k)
    assert wire == [b"0", b"5", b"10"]
    p.control(Control(tick=11, seq=1, paused=True))
    assert not p.ready(12) and wire[-1] == b"11"  # a held match shows the tick it holds
    assert not p.ready(12) and wire.count(b"11") == 1  # once
    p.control(Control(tick=11, seq=2, paused=True, step=1))
    assert p.ready(12)
    gate(b"12")
    assert not p.ready(13) and wire[-1] == b"12" and gate.passed == len(wire) == 5
    gate.flush()
    assert len(wire) == 5  # nothing held: nothing sent twice


def test_a_paced_tick_is_ready_when_the_clock_reaches_its_time():
    clock = ManualClock()
    p = Pacer(0.02, 1.0, clock=clock)
    assert p.ready(0)  # the schedule counts from here
    assert not p.ready(5)  # 0.1 s later at real-time pace
    clock.advance(0.05)
    assert not p.ready(5)
    clock.advance(0.05)
    assert p.ready(5)
    p.pace = 2.0  # twice real time: tick 10 is due 0.05 s after tick 5's time, from the same anchor
    clock.advance(BEHIND_S + 0.1)  # far behind: the schedule restarts from now instead of sprinting
    assert p.ready(6) and not p.ready(7)
    clock.advance(0.01)
    assert p.ready(7)


def test_sync_blocks_until_the_clock_reaches_the_tick():
    clock = ManualClock()
    p = Pacer(0.02, 1.0, clock=clock)
    assert p.ready(0)
    done = threading.Event()
    t = threading.Thread(target=lambda: (p.sync(10), done.set()), daemon=True)
    t.start()
    clock.until_sleeping()
    clock.advance(0.1)
    assert not done.is_set(), "tick 10 is due at 0.2 s"
    clock.advance(0.1)
    t.join(5.0)
    assert done.is_set()


def test_the_reactive_pacer_pokes_the_loop_when_a_tick_is_due():
    clock = ManualClock()
    p = Pacer(0.02, 1.0, clock=clock)
    pokes: list[float] = []
    assert p.ready(0) and not p.ready(20)  # due at 0.4 s
    p.start(lambda: pokes.append(clock.monotonic()))
    try:
        clock.until_sleeping()  # its thread waits for tick 20's time
        clock.advance(0.3)
        assert pokes == []
        clock.advance(0.1)
        assert pokes == [0.4] and p.ready(20)
    finally:
        p.stop()


def test_malformed_control_frames_are_rejected_not_applied():
    p = Pacer(0.02, 0.0)
    assert p.control_raw(b"\xc1") is not None
    assert p.control_raw(encode(Control(tick=0, seq=0, paused=True))) is None
    assert p.paused


@pytest.mark.parametrize(
    "changes",
    [dict(live=70000), dict(pace=-1.0), dict(pace=2.0), dict(live=8765, pace=2.0, realtime=True)],
)
def test_bad_live_configurations_are_config_errors(changes):
    with pytest.raises(ConfigError):
        MatchConfig(**changes).validate()


def test_a_live_match_has_a_viewer_process():
    assert "viewer" in [p.kind for p in MatchConfig(live=0).processes()]
    assert "viewer" not in [p.kind for p in MatchConfig().processes()]


@pytest.mark.parametrize(
    "flags",
    [["--pace", "2"], ["--live", "8765", "--realtime", "--pace", "2"], ["--live", "99999"], ["--live", "x"]],
)
def test_cli_rejects_bad_live_flags_with_one_line_and_exit_2(flags, capfd):
    argv = ["match", "--home", "BS", "--away", "BS", *flags]
    if flags == ["--pace", "2"]:  # one as a real process; the others through its entry point here
        r = subprocess.run([sys.executable, "-m", "arena", *argv], capture_output=True, text=True, timeout=60)
    else:
        r = arena_in_process(argv, capfd)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_a_control_seq_that_jumps_past_the_window_is_refused_and_the_viewer_keeps_control():
    """One forged `{"seq": 2**62, "paused": true}` held a live match paused for good: every genuine frame
    after it had a lower seq. A frame may be at most SEQ_WINDOW past the last one (the viewer counts by one)."""
    from arena.runtime.pace import SEQ_WINDOW

    p = Pacer(0.02, 0.0)
    assert p.control(Control(tick=0, seq=2**62, paused=True)) == (
        "out-of-sequence",
        f"seq {2**62} jumps more than {SEQ_WINDOW} past -1",
    )
    assert not p.paused and p.ready(0)
    assert p.control(Control(tick=0, seq=1, paused=True)) is None and p.paused
    assert p.control_raw(encode(Control(tick=0, seq=1 + SEQ_WINDOW + 1, paused=False)))[0] == "out-of-sequence"
    assert p.paused and p.control(Control(tick=0, seq=1 + SEQ_WINDOW, paused=False)) is None and not p.paused


def test_a_pause_in_pull_mode_lasts_at_most_its_timeout():
    """Real time on purpose: the bound is the pacer's own wall-clock wait."""
    import time

    p = Pacer(0.02, 0.0, timeout=0.2)
    p.control(Control(tick=0, seq=1, paused=True))
    t0 = time.monotonic()
    p.sync(0)
    assert 0.2 <= time.monotonic() - t0 < 5.0 and not p.paused


def test_a_pause_holds_a_reactive_engine_no_longer_than_its_wait_timeout():
    """The Reactor bounds the pacer's wait as any other (runtime/drivers.py `_look`): then it plays on."""
    import threading

    from arena.runtime.clock import ManualClock
    from arena.runtime.drivers import Reactor

    clock = ManualClock()
    p = Pacer(0.02, 0.0)
    p.control(Control(tick=0, seq=1, paused=True))  # a pause set before the start holds tick 0
    played: list[int] = []

    def loop():
        for k in range(3):
            yield p, k
            played.append(k)

    reactor = Reactor(timeout=0.3, clock=clock)
    runner = threading.Thread(target=reactor.run, args=(loop(),))
    runner.start()
    clock.until_sleeping(1)
    clock.advance(0.1)
    assert played == [] and runner.is_alive(), "held while paused"
    for _ in range(4):
        clock.advance(0.1)
    runner.join(5.0)
    assert not runner.is_alive() and played == [0, 1, 2] and not p.paused
