"""Invalid frames, conflicting senders, parked robots and the honest outcome, unit by unit."""

from __future__ import annotations

import math

import msgspec
import pytest

from arena.config import MatchConfig
from arena.match.faults import Fault, blame, lapses, outcome
from arena.schemas.messages import Cmd, EngineEvents, Order, RefCommand, Referee, Summary, TeamPose, encode
from arena.schemas.validate import nonfinite, safe_default, starts_nonfinite, suspect
from arena.sim.physics import Physics
from tests.unit.test_lockstep import Harness


@pytest.mark.parametrize(
    "msg",
    [
        Cmd(tick=3, vx=math.nan),
        Cmd(tick=3, wheels=[1.0, -math.inf, 0.0, 0.0], mode="wheels"),
        Order(tick=3, robot=1, own=[TeamPose(robot=1, x=math.inf, y=0.0)]),
        Referee(tick=3, stage="FIRST_HALF", command="STOP", commands=[RefCommand(name="STOP", x=math.nan)]),
    ],
)
def test_a_non_finite_float_anywhere_is_found(msg):
    raw = encode(msg)
    assert nonfinite(raw, msgspec.msgpack.decode(raw, type=type(msg)))


def test_a_clean_message_costs_only_the_byte_scan():
    raw = encode(Order(tick=3, robot=1, ball_x=1e308, own=[TeamPose(robot=1, x=1.0, y=2.0)]))
    assert nonfinite(raw, msgspec.msgpack.decode(raw, type=Order)) is None


def test_safe_defaults():
    assert safe_default(Cmd(tick=7, vx=math.nan, kick_speed=5.0), None) == Cmd(tick=7)
    assert safe_default(EngineEvents(tick=9), None) == EngineEvents(tick=9)
    prev = Referee(tick=5, stage="FIRST_HALF", command="START", commands=[RefCommand(name="START")])
    assert safe_default(Referee(tick=10, stage="?", command="?"), prev) == Referee(
        tick=10, stage="FIRST_HALF", command="START"
    )
    assert safe_default(Order(tick=6, robot=1, ball_x=math.nan), None) is None
    assert safe_default(Order(tick=11, robot=1, ball_x=math.nan), Order(tick=6, robot=1, ball_x=2.0)).ball_x == 2.0


def test_an_invalid_frame_in_sequence_advances_its_link_with_wheels_stopped():
    h = Harness()
    h.inbound._check = lambda c: "too fast" if c.vx > 10 else None
    h.put(encode(Cmd(tick=0, vx=1.0)))
    h.put(encode(Cmd(tick=1, vx=math.nan, kick_speed=3.0)))
    h.put(encode(Cmd(tick=2, vx=99.0)))
    h.put(encode(Cmd(tick=3, vx=2.0)))
    h.inbound.sync(4)
    h.close()
    assert h.inbound.last_seen == 3 and h.rej.by_reason == {"invalid": 2}
    assert [(c.tick, c.vx, c.kick_speed) for c in h.inbound.take(4)] == [(0, 1.0, 0), (1, 0, 0), (2, 0, 0), (3, 2.0, 0)]


def test_a_second_different_frame_for_a_tick_is_a_conflict_and_a_repeat_is_not():
    h = Harness()
    h.put(encode(Cmd(tick=0, vx=-5.0)))  # the forger is first
    h.put(encode(Cmd(tick=0, vx=1.0)))  # the real robot
    h.put(encode(Cmd(tick=0, vx=1.0)))  # a repeat of the forged one would be the same bytes: not this
    h.put(encode(Cmd(tick=1)))
    h.put(encode(Cmd(tick=1)))  # the same frame twice: only out of sequence
    h.put(encode(Cmd(tick=2)))
    h.inbound.sync(3)
    h.close()
    assert h.rej.conflicts == {h.inbound.key: 2}
    assert h.rej.by_reason == {"conflict": 2, "out-of-sequence": 1}


def test_a_parked_robot_leaves_the_field_for_good():
    cfg = MatchConfig(seed=1)
    ph = Physics(cfg)
    ph.kickoff_positions("a")
    x, y = ph.park_robot("b", 1)
    assert abs(x) > cfg.field.length / 2 + cfg.field.runoff
    ph.set_command("b", 1, Cmd(tick=0, vx=2.0))
    ph.kickoff_positions("b")
    ph.place_robot("b", 1, 0.0, 0.0, 0.0)
    ph.start_play()
    for _ in range(50):
        ph.step()
    px, py, _ = ph.robot_pose("b", 1)
    assert (px, py) == pytest.approx((x, y), abs=1e-9)
    assert ph.parked() == [("b", 1)]


def _summary(process, dead=(), dead_at=None, tick=100, conflicts=None, silent=None):
    return Summary(tick=tick, process=process, pid=1, digest="", sent=0, rejected=0, dead=list(dead),
                   dead_at=dead_at or {}, conflicts=conflicts or {},
                   extra={"silent": silent} if silent else {})  # fmt: skip


def test_a_peer_found_silent_while_alive_is_blamed_not_the_one_that_waited():
    """Issue 20: a robot sends its cmd but never its report. Its base station gives up on it (it was alive,
    and not waiting itself); muted, the robot later finds its base station silent too. Only it is dead."""
    sums = {
        "engine": _summary("engine"),
        "basestation/a": _summary("basestation/a", ["robot/a/1"], {"robot/a/1": 1}, silent={"robot/a/1": 1}),
        "robot/a/1": _summary("robot/a/1", ["basestation/a"], {"basestation/a": 210}, silent={"basestation/a": 210}),
        "robot/a/2": _summary("robot/a/2"),
    }
    assert blame(sums, set()) == {"robot/a/1": 1}


def test_a_process_that_was_lost_itself_blames_nobody():
    """Issue 20: after a 10 s SIGSTOP, the stopped robot sees everyone vanish; only it is dead."""
    sums = {
        "engine": _summary("engine", ["robot/a/1"], {"robot/a/1": 40}),
        "basestation/a": _summary("basestation/a", ["robot/a/1"], {"robot/a/1": 36}),
        "robot/a/1": _summary("robot/a/1", ["basestation/a", "engine"], {"engine": 39}),
    }
    assert blame(sums, {"robot/a/1"}) == {"robot/a/1": 40}


def test_outcomes():
    cfg = MatchConfig(seed=1, half_time=1.0)
    full = {str(p): _summary(str(p), tick=cfg.total_ticks) for p in cfg.processes()}
    assert outcome(cfg, full, {}, {}, {}).outcome == "completed"
    crashed = dict(full)
    crashed.pop("robot/b/1")
    crashed["engine"] = _summary("engine", ["robot/b/1"], {"robot/b/1": 20}, tick=cfg.total_ticks)
    o = outcome(cfg, crashed, {"robot/b/1": "exited with code -9 (SIGKILL)"}, {}, {})
    assert o.outcome == "completed_with_faults" and o.faults == [
        Fault(process="robot/b/1", tick=20, reason="exited with code -9 (SIGKILL)")
    ]
    short = dict(full, engine=_summary("engine", tick=10))
    assert outcome(cfg, short, {}, {}, {}).outcome_reasons == [f"the engine played 10 of {cfg.total_ticks} ticks"]
    noref = dict(full)
    noref.pop("referee")
    o = outcome(cfg, noref, {"referee": "exited with code 1"}, {}, {}, void="referee exited with code 1")
    assert o.void and o.outcome_reasons == ["referee exited with code 1"]
    spoofed = dict(full, engine=_summary("engine", tick=cfg.total_ticks, conflicts={"robot/b/1/cmd": 3}))
    assert outcome(cfg, spoofed, {}, {}, {}).conflicts == {"robot/b/1/cmd": 3}


def test_a_process_that_lost_everyone_while_nobody_lost_it_is_the_one_blamed():
    """The other outcome of a 10 s SIGSTOP: the others just waited, the stopped robot saw them all vanish."""
    sums = {
        "engine": _summary("engine"),
        "basestation/a": _summary("basestation/a"),
        "robot/a/1": _summary("robot/a/1", ["basestation/a", "engine"], {"engine": 1012, "basestation/a": 1011}),
    }
    assert blame(sums, set()) == {"robot/a/1": 1011}


def test_the_one_scan_finds_exactly_the_four_suspect_pairs():
    """suspect() is the four scans it replaced (0xca/0xcb then 0x7f/0xff), for every pair of bytes."""
    pairs = (b"\xcb\x7f", b"\xcb\xff", b"\xca\x7f", b"\xca\xff")
    for a in range(256):
        for b in range(256):
            raw = bytes([0x93, a, b, 0x01])
            assert suspect(raw) == any(p in raw for p in pairs), raw
    assert not suspect(b"") and suspect(msgspec.msgpack.encode([1.0, float("-inf")]))


def test_a_suspect_pair_starts_a_non_finite_value_only_if_the_exponents_next_bits_are_set_too():
    """starts_nonfinite: a float64's exponent is 11 bits (0xf0 and over next), a float32's 8 (0x80 and over)."""
    import struct

    for head, least in ((0xCB, 0xF0), (0xCA, 0x80)):
        for first in (0x7F, 0xFF):
            for b in range(256):
                raw = bytes([0x81, 0xA1, 0x78, head, first, b, 0, 0, 0, 0, 0, 0, 0])
                assert starts_nonfinite(raw) == (b >= least), raw
    for x in (math.nan, math.inf, -math.inf, -math.nan):
        assert starts_nonfinite(struct.pack(">Bd", 0xCB, x)) and starts_nonfinite(struct.pack(">Bf", 0xCA, x))
    # A float's other bytes hold a pair: not walked, no problem; a pair cut short: walked.
    clean = encode(Cmd(tick=1, vx=1.0)).replace(struct.pack(">d", 1.0), b"\x3f\xf0\xcb\x7f\x00\x00\x00\x00")
    assert (
        suspect(clean)
        and not starts_nonfinite(clean)
        and nonfinite(clean, msgspec.msgpack.decode(clean, type=Cmd)) is None
    )
    assert starts_nonfinite(b"\x92\x01\xcb\xff")


def test_a_token_that_lapsed_under_load_is_no_fault_unless_a_peer_gave_up_on_it():
    """Issue 36: a flood of forged frames on the router made the launcher lose leases of processes
    that never stopped (once all 11: "engine: its liveliness token vanished mid-match"). A lapse is
    a failure only if a peer gave up waiting for the process's frames; else its frames kept coming."""
    sums = {
        "engine": _summary("engine", ["robot/a/1"], {"robot/a/1": 40}),
        "referee": _summary("referee"),
        "robot/a/1": _summary("robot/a/1"),
        "robot/a/2": _summary("robot/a/2"),
    }
    lost, lapsed = lapses({"engine", "referee", "robot/a/1", "robot/a/2", "robot/b/0"}, sums)
    assert lost == {"robot/a/1", "robot/b/0"}, "the engine gave up on a/1; b/0 sent no summary"
    assert lapsed == {"engine", "referee", "robot/a/2"}


def test_a_failed_engine_or_referee_voids_the_match_even_with_its_summary():
    """Issue 36: an engine that stopped for a while (its peers gave up on it) and came back for its
    summary was a fault of a match `completed_with_faults`; without the engine there is no game."""
    cfg = MatchConfig(seed=1, half_time=1.0)
    full = {str(p): _summary(str(p), tick=cfg.total_ticks) for p in cfg.processes()}
    full["robot/a/1"] = _summary("robot/a/1", ["engine"], {"engine": 30}, tick=cfg.total_ticks)
    why = "stopped responding for a while: its liveliness token vanished mid-match"
    o = outcome(cfg, full, {}, {"engine": why}, {})
    assert o.outcome == "void" and o.void, o
    assert o.outcome_reasons == [f"engine: {why}"]
    assert [f.process for f in o.faults] == ["engine"]
    o = outcome(cfg, full, {}, {"referee": why}, {})
    assert o.outcome == "void" and o.outcome_reasons == [f"referee: {why}"]


def test_forged_counts_are_said_to_be_messages():
    """Forged ones are counted per zenoh message (one may batch several frames), conflicting ones
    per frame; the line said "frames" for both."""
    from types import SimpleNamespace

    from arena.match.faults import warnings

    result = SimpleNamespace(
        forged={"arena/m/cmd/a/1": 3, "arena/m/referee": 1}, conflicts={"arena/m/referee": 2}, faults=[]
    )
    lines = warnings(result)
    assert lines == [
        "possible spoofing on arena/m/cmd/a/1 (3 forged messages)",
        "possible spoofing on arena/m/referee (1 forged message, 2 conflicting frames)",
    ]


@pytest.mark.parametrize("period", [1, 5])
def test_a_different_frame_is_a_conflict_within_the_last_recent_frames_and_out_of_sequence_long_before(period):
    """The kept window (runtime/lockstep.py `RECENT`): a different frame for any of (at least) the last
    RECENT accepted ticks is a conflict, a repeat of one is not; a frame far older is only out of sequence."""
    from arena.runtime.lockstep import RECENT, Schedule

    h = Harness(schedule=Schedule(period, 0))
    last = 4 * RECENT * period  # frames: far more than the window keeps
    for i in range(last + 1):
        h.put(encode(Cmd(tick=i * period, vx=1.0)))
    oldest = (last - RECENT + 1) * period  # the oldest tick of the last RECENT frames
    h.put(encode(Cmd(tick=oldest, vx=2.0)))  # a conflict
    h.put(encode(Cmd(tick=oldest, vx=1.0)))  # a repeat: out of sequence
    h.put(encode(Cmd(tick=last * period, vx=2.0)))  # a conflict
    h.put(encode(Cmd(tick=period, vx=2.0)))  # long before the window: out of sequence
    if period > 1:
        h.put(encode(Cmd(tick=oldest + 1, vx=2.0)))  # never a tick of the link: out of sequence
    h.inbound.sync(last * period + 1)
    h.inbound.drain()  # what came after
    h.close()
    assert h.inbound.last_seen == last * period
    assert h.rej.conflicts == {h.inbound.key: 2}, h.rej.by_reason
    assert h.rej.by_reason == {"conflict": 2, "out-of-sequence": 3 if period > 1 else 2}
