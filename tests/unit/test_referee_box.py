"""The referee box as a pure state machine: table-driven, state + event -> commands."""

from __future__ import annotations

import pytest

from arena.processes.referee_box import RefereeBox, RefereeState
from arena.runtime.config import MatchConfig
from arena.schemas.messages import BallEvent

CFG = MatchConfig(half_time=10.0)  # 500 ticks per half
HALF, END = CFG.half_ticks, CFG.total_ticks


def box_in(**state) -> RefereeBox:
    box = RefereeBox(CFG)
    box.state = RefereeState(**state)
    return box


def goal(team: str) -> BallEvent:
    return BallEvent(kind="GOAL", tick=100, team=team, x=6.2, y=0.1)


PLAYING = dict(stage="FIRST_HALF", command="START", command_team="a")

CASES = [
    # name, initial state, tick, events, expected (name, team) commands, expected score
    ("kickoff opens the match", dict(), 0, [], [("FIRST_HALF", ""), ("KICKOFF", "a")], (0, 0)),
    (
        "goal by a: conceding b kicks off",
        PLAYING,
        100,
        [goal("a")],
        [("GOAL", "a"), ("STOP", ""), ("KICKOFF", "b")],
        (1, 0),
    ),
    ("goal by b", PLAYING, 100, [goal("b")], [("GOAL", "b"), ("STOP", ""), ("KICKOFF", "a")], (0, 1)),
    ("goal while stopped does not count", dict(stage="FIRST_HALF", command="STOP"), 100, [goal("a")], [], (0, 0)),
    (
        "touch line: drop ball inside the field",
        PLAYING,
        100,
        [BallEvent(kind="TOUCH_LINE", tick=99, x=1.0, y=4.2, last_team="a")],
        [("STOP", ""), ("DROP_BALL", "")],
        (0, 0),
    ),
    (
        "no progress: drop ball",
        PLAYING,
        100,
        [BallEvent(kind="NO_PROGRESS", tick=99, x=5.9, y=-3.9)],
        [("STOP", ""), ("DROP_BALL", "")],
        (0, 0),
    ),
    (
        "half time switches sides, b kicks off",
        PLAYING,
        HALF,
        [],
        [("HALF_TIME", ""), ("SECOND_HALF", ""), ("KICKOFF", "b")],
        (0, 0),
    ),
    ("end of the match", dict(stage="SECOND_HALF", command="START"), END, [], [("END_GAME", "")], (0, 0)),
    ("nothing after the end", dict(stage="END_GAME", command="END_GAME"), END + 5, [goal("a")], [], (0, 0)),
    ("start after positioning time", dict(stage="FIRST_HALF", command="KICKOFF", command_team="b", start_at=150), 150, [], [("START", "b")], (0, 0)),
    ("no start before positioning time", dict(stage="FIRST_HALF", command="KICKOFF", command_team="b", start_at=150), 145, [], [], (0, 0)),
]


@pytest.mark.parametrize(("name", "state", "tick", "events", "want", "score"), CASES, ids=[c[0] for c in CASES])
def test_rule(name, state, tick, events, want, score):
    box = box_in(**state)
    got = box.step(tick, events)
    assert [(c.name, c.team) for c in got] == want
    assert (box.state.score["a"], box.state.score["b"]) == score


def test_half_time_flips_attack_direction_and_goals_keep_counting():
    box = box_in(**PLAYING)
    box.step(HALF, [])
    assert box.state.attack_dir_a == -1
    box.state.command = "START"
    box.step(HALF + 5, [goal("b")])
    assert box.state.score == {"a": 0, "b": 1}


def test_drop_ball_spot_is_one_metre_inside_the_lines():
    box = box_in(**PLAYING)
    cmds = box.step(100, [BallEvent(kind="GOAL_LINE", tick=99, x=6.3, y=-3.95)])
    drop = next(c for c in cmds if c.name == "DROP_BALL")
    assert (drop.x, drop.y) == (5.0, -3.0)


def test_event_log_is_append_only_with_states():
    box = RefereeBox(CFG)
    box.step(0, [])
    box.state.command = "START"
    box.step(100, [goal("a")])
    assert [e.command.name for e in box.log] == ["FIRST_HALF", "KICKOFF", "GOAL", "STOP", "KICKOFF"]
    assert box.log[0].stage_before == "PRE_GAME" and box.log[0].stage_after == "FIRST_HALF"
    assert box.log[2].score == (1, 0)
