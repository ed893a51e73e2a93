"""The referee box as a pure state machine: table-driven, (state, change) -> (state, commands).

One row per rule of docs/rules.md; the row's id is what the rules table cites.
"""

from __future__ import annotations

import dataclasses

import pytest

from arena.config import MatchConfig
from arena.rules.referee_box import (
    Clock,
    Observed,
    RefereeBox,
    RefereeState,
    Rules,
    check_referee,
    clock_due,
    on_clock,
    process,
)
from arena.schemas.messages import BallEvent, RefCommand, Referee

CFG = MatchConfig(half_time=10.0)  # 500 ticks per half
RULES = Rules.of(CFG)
HALF, END = CFG.half_ticks, CFG.total_ticks
KICKOFF_WAIT, SETPIECE_WAIT, TAKE = RULES.kickoff_ticks, RULES.setpiece_ticks, RULES.take_ticks

PLAYING = dict(stage="FIRST_HALF", command="START", command_team="a", issued_at=90)
SECOND = dict(stage="SECOND_HALF", command="START", command_team="b", issued_at=90, attack_dir_a=-1)


def ev(kind: str, tick: int = 99, **kw) -> Observed:
    return Observed(100, BallEvent(kind=kind, tick=tick, **kw))


# name, initial state, change, expected [(command, team, spot)], expected state fields
CASES = [
    # --------------------------------------------------------------- clock
    (
        "pre-game: FIRST_HALF and KICKOFF for a",
        dict(),
        Clock(0),
        [("FIRST_HALF", "", (0, 0)), ("KICKOFF", "a", (0, 0))],
        dict(stage="FIRST_HALF", command="KICKOFF", start_at=KICKOFF_WAIT),
    ),
    (
        "positioning over: START for the set piece's team",
        dict(stage="FIRST_HALF", command="THROWIN", command_team="b", spot=(1.0, 4.0), start_at=150),
        Clock(150),
        [("START", "b", (1.0, 4.0))],
        dict(command="START", start_at=-1, take_by=150 + TAKE, issued_at=150),
    ),
    (
        "no START before the positioning time is over",
        dict(stage="FIRST_HALF", command="THROWIN", command_team="b", start_at=150),
        Clock(145),
        [],
        dict(command="THROWIN", start_at=150),
    ),
    (
        "drop ball: START for both, nothing to take",
        dict(stage="FIRST_HALF", command="DROP_BALL", spot=(2.0, 1.0), start_at=150),
        Clock(150),
        [("START", "", (2.0, 1.0))],
        dict(command="START", take_by=-1),
    ),
    (
        "half time: sides switch, b kicks off",
        PLAYING,
        Clock(HALF),
        [("HALF_TIME", "", (0, 0)), ("SECOND_HALF", "", (0, 0)), ("KICKOFF", "b", (0, 0))],
        dict(stage="SECOND_HALF", attack_dir_a=-1, command="KICKOFF", start_at=HALF + KICKOFF_WAIT),
    ),
    (
        "end of the match: END_GAME, PARK, GAMEOVER",
        SECOND,
        Clock(END),
        [("END_GAME", "", (0, 0)), ("PARK", "", (0, 0)), ("GAMEOVER", "", (0, 0))],
        dict(stage="END_GAME", command="END_GAME", start_at=-1),
    ),
    ("nothing after the end", dict(stage="END_GAME", command="END_GAME"), Clock(END + 5), [], dict(stage="END_GAME")),
    (
        "set piece not taken in time: drop ball on its spot",
        dict(PLAYING, command_team="b", spot=(2.0, 4.0), take_by=400),
        Clock(400),
        [("STOP", "", (0, 0)), ("DROP_BALL", "", (2.0, 4.0))],
        dict(command="DROP_BALL", start_at=400 + SETPIECE_WAIT, take_by=-1),
    ),
    (
        "a touch after START takes the set piece",
        dict(PLAYING, take_by=400),
        ev("TOUCH", team="a", robot=1),
        [],
        dict(take_by=-1),
    ),
    # --------------------------------------------------------------- goals
    (
        "goal by a: counts, b kicks off",
        PLAYING,
        ev("GOAL", team="a", x=6.2, y=0.1),
        [("GOAL", "a", (0, 0)), ("STOP", "", (0, 0)), ("KICKOFF", "b", (0, 0))],
        dict(score=(1, 0), command="KICKOFF", command_team="b", start_at=100 + KICKOFF_WAIT),
    ),
    (
        "goal by b: counts, a kicks off",
        PLAYING,
        ev("GOAL", team="b", x=-6.2, y=0.1),
        [("GOAL", "b", (0, 0)), ("STOP", "", (0, 0)), ("KICKOFF", "a", (0, 0))],
        dict(score=(0, 1)),
    ),
    (
        "goal in the second half counts for the scorer",
        dict(SECOND, score=(2, 1)),
        ev("GOAL", team="a", x=-6.2),
        [("GOAL", "a", (0, 0)), ("STOP", "", (0, 0)), ("KICKOFF", "b", (0, 0))],
        dict(score=(3, 1)),
    ),
    (
        "ball not in play: events are ignored",
        dict(stage="FIRST_HALF", command="STOP"),
        ev("GOAL", team="a"),
        [],
        dict(score=(0, 0)),
    ),
    (
        "event from before START is stale",
        dict(PLAYING, issued_at=99),
        ev("GOAL", team="a", tick=99),
        [],
        dict(score=(0, 0)),
    ),
    # -------------------------------------------------------- ball out
    (
        "touch line, a touched last: THROWIN b on the line",
        PLAYING,
        ev("TOUCH_LINE", x=1.3, y=4.2, last_team="a", last_robot=2),
        [("STOP", "", (0, 0)), ("THROWIN", "b", (1.3, 4.0))],
        dict(command="THROWIN", command_team="b"),
    ),
    (
        "touch line, b touched last: THROWIN a, kept off the goal line",
        PLAYING,
        ev("TOUCH_LINE", x=-5.95, y=-4.2, last_team="b", last_robot=1),
        [("STOP", "", (0, 0)), ("THROWIN", "a", (-5.5, -4.0))],
        dict(command_team="a"),
    ),
    (
        "touch line, nobody touched: drop ball",
        PLAYING,
        ev("TOUCH_LINE", x=0.0, y=4.2),
        [("STOP", "", (0, 0)), ("DROP_BALL", "", (0.0, 3.0))],
        dict(command="DROP_BALL"),
    ),
    (
        "goal line, attacker touched last: GOALKICK for the defender",
        PLAYING,
        ev("GOAL_LINE", team="b", x=6.2, y=2.5, last_team="a", last_robot=1),
        [("STOP", "", (0, 0)), ("GOALKICK", "b", (5.5, 1.5))],
        dict(command="GOALKICK"),
    ),
    (
        "goal line, defender touched last: CORNER for the attacker",
        PLAYING,
        ev("GOAL_LINE", team="b", x=6.2, y=-2.5, last_team="b", last_robot=0),
        [("STOP", "", (0, 0)), ("CORNER", "a", (5.75, -3.75))],
        dict(command="CORNER", command_team="a"),
    ),
    (
        "goal line without a team: the defender from the side, after the switch",
        SECOND,
        ev("GOAL_LINE", x=-6.2, y=2.0, last_team="a"),
        [("STOP", "", (0, 0)), ("GOALKICK", "b", (-5.5, 1.5))],
        dict(command_team="b"),
    ),
    (
        "no progress: drop ball 1 m inside the lines",
        PLAYING,
        ev("NO_PROGRESS", x=5.9, y=-3.9),
        [("STOP", "", (0, 0)), ("DROP_BALL", "", (5.0, -3.0))],
        dict(start_at=100 + SETPIECE_WAIT),
    ),
    # ------------------------------------------------------------- fouls
    (
        "pushing by a: FREEKICK b where it happened",
        PLAYING,
        ev("FOUL_PUSHING", team="a", robot=1, x=1.0, y=2.0),
        [("STOP", "", (0, 0)), ("FREEKICK", "b", (1.0, 2.0))],
        dict(command="FREEKICK", command_team="b"),
    ),
    (
        "dribbling by b: FREEKICK a, kept inside the lines",
        PLAYING,
        ev("FOUL_DRIBBLING", team="b", robot=2, x=-2.0, y=3.9),
        [("STOP", "", (0, 0)), ("FREEKICK", "a", (-2.0, 3.5))],
        dict(command_team="a"),
    ),
    (
        "foul by an attacker in the other penalty area: free kick on its front line",
        PLAYING,
        ev("FOUL_PUSHING", team="a", robot=1, x=5.5, y=0.5),
        [("STOP", "", (0, 0)), ("FREEKICK", "b", (4.5, 0.5))],
        dict(),
    ),
    (
        "foul by a defender in its own penalty area: PENALTY on the mark",
        PLAYING,
        ev("FOUL_PUSHING", team="b", robot=1, x=5.5, y=0.5),
        [("STOP", "", (0, 0)), ("PENALTY", "a", (4.0, 0.0))],
        dict(command="PENALTY", command_team="a", spot=(4.0, 0.0), start_at=100 + SETPIECE_WAIT),
    ),
    (
        "penalty after the switch: the mark of the defender's goal",
        SECOND,
        ev("FOUL_DRIBBLING", team="a", robot=2, x=5.2, y=-2.0),
        [("STOP", "", (0, 0)), ("PENALTY", "b", (4.0, 0.0))],
        dict(command_team="b"),
    ),
    (
        "penalty START: it must be taken",
        dict(stage="FIRST_HALF", command="PENALTY", command_team="a", spot=(4.0, 0.0), start_at=150),
        Clock(150),
        [("START", "a", (4.0, 0.0))],
        dict(take_by=150 + TAKE),
    ),
    # ------------------------------------------------------------- cards
    (
        "a robot's first foul: counted, no card",
        PLAYING,
        ev("FOUL_PUSHING", team="a", robot=1, x=1.0, y=2.0),
        [("STOP", "", (0, 0)), ("FREEKICK", "b", (1.0, 2.0))],
        dict(fouls=(("a", 1, 1),), off=()),
    ),
    (
        "its second foul: YELLOW_CARD between STOP and the free kick",
        dict(PLAYING, fouls=(("a", 1, 1), ("b", 2, 1))),
        ev("FOUL_DRIBBLING", team="a", robot=1, x=1.0, y=2.0),
        [("STOP", "", (0, 0)), ("YELLOW_CARD", "a", (1.0, 2.0)), ("FREEKICK", "b", (1.0, 2.0))],
        dict(fouls=(("a", 1, 2), ("b", 2, 1)), off=(), command="FREEKICK"),
    ),
    (
        "another robot's first foul: no card",
        dict(PLAYING, fouls=(("a", 1, 1),)),
        ev("FOUL_PUSHING", team="a", robot=2, x=1.0, y=2.0),
        [("STOP", "", (0, 0)), ("FREEKICK", "b", (1.0, 2.0))],
        dict(fouls=(("a", 1, 1), ("a", 2, 1))),
    ),
    (
        "its fourth foul: DOUBLE_YELLOW, sent off",
        dict(PLAYING, fouls=(("b", 2, 3),)),
        ev("FOUL_PUSHING", team="b", robot=2, x=-1.0, y=0.0),
        [("STOP", "", (0, 0)), ("DOUBLE_YELLOW", "b", (-1.0, 0.0)), ("FREEKICK", "a", (-1.0, 0.0))],
        dict(fouls=(("b", 2, 4),), off=(("b", 2),)),
    ),
    (
        "a foul without a robot: no card",
        PLAYING,
        ev("FOUL_PUSHING", team="a", x=1.0, y=2.0),
        [("STOP", "", (0, 0)), ("FREEKICK", "b", (1.0, 2.0))],
        dict(fouls=()),
    ),
    (
        "a dead robot: REPAIR_OUT, play goes on",
        PLAYING,
        ev("ROBOT_DEAD", team="a", robot=2),
        [("REPAIR_OUT", "a", (0, 0))],
        dict(command="START", off=(("a", 2),)),
    ),
    (
        "a dead robot while play is stopped: REPAIR_OUT all the same",
        dict(stage="FIRST_HALF", command="FREEKICK", command_team="a", start_at=150),
        ev("ROBOT_DEAD", team="b", robot=0),
        [("REPAIR_OUT", "b", (0, 0))],
        dict(command="FREEKICK", off=(("b", 0),)),
    ),
    (
        "a stuck robot: REPAIR_OUT, play goes on",
        PLAYING,
        ev("ROBOT_STUCK", team="b", robot=1, x=2.0, y=4.6),
        [("REPAIR_OUT", "b", (0, 0))],
        dict(command="START", off=(("b", 1),)),
    ),
    (
        "a robot already off: no second REPAIR_OUT",
        dict(PLAYING, off=(("a", 2),)),
        ev("ROBOT_DEAD", team="a", robot=2),
        [],
        dict(off=(("a", 2),)),
    ),
]


@pytest.mark.parametrize(("name", "state", "change", "want", "fields"), CASES, ids=[c[0] for c in CASES])
def test_rule(name, state, change, want, fields):
    pre = RefereeState(**state)
    post, cmds = process(pre, change, RULES)
    got = [(c.name, c.team, (pytest.approx(c.x), pytest.approx(c.y))) for c in cmds]
    assert got == [(n, t, tuple(s)) for n, t, s in want]
    for key, value in fields.items():
        assert getattr(post, key) == value, key
    tick = change.tick
    assert all(c.tick == tick for c in cmds)
    assert [c.robot >= 0 for c in cmds] == [
        c.name in ("YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW", "REPAIR_OUT") for c in cmds
    ]
    assert check_referee(Referee(tick=tick, stage="FIRST_HALF", command="START", commands=cmds)) is None


RED = Rules.of(dataclasses.replace(CFG, rules=dataclasses.replace(CFG.rules, red_fouls=3)))


@pytest.mark.parametrize(
    ("fouls", "card"),
    [(1, None), (2, "YELLOW_CARD"), (3, None), (4, "DOUBLE_YELLOW"), (5, None)],
)
def test_card_thresholds_default(fouls, card):
    from arena.rules.referee_box import card_rule

    assert card_rule(fouls, RULES) == card


def test_red_card_threshold_sends_the_robot_off():
    pre = RefereeState(**PLAYING, fouls=(("a", 3, 2),))
    post, cmds = process(pre, ev("FOUL_PUSHING", team="a", robot=3, x=0.0, y=0.0), RED)
    assert [(c.name, c.team, c.robot) for c in cmds] == [("STOP", "", -1), ("RED_CARD", "a", 3), ("FREEKICK", "b", -1)]
    assert post.off == (("a", 3),) and post.fouls == (("a", 3, 3),)


def test_process_is_pure():
    pre = RefereeState(**PLAYING)
    copy = dataclasses.replace(pre)
    post, _ = process(pre, ev("GOAL", team="a"), RULES)
    assert pre == copy and post != pre


def test_match_flow_and_append_only_log():
    box = RefereeBox(CFG)
    assert [c.name for c in box.step(0, [])] == ["FIRST_HALF", "KICKOFF"]
    assert [c.name for c in box.step(KICKOFF_WAIT, [])] == ["START"]
    goal = BallEvent(kind="GOAL", tick=KICKOFF_WAIT + 3, team="a", x=6.2)
    assert [c.name for c in box.step(KICKOFF_WAIT + 5, [goal])] == ["GOAL", "STOP", "KICKOFF"]
    box.step(HALF, [])
    box.step(END, [])
    names = [c.name for e in box.log for c in e.commands]
    assert names == [
        "FIRST_HALF",
        "KICKOFF",
        "START",
        "GOAL",
        "STOP",
        "KICKOFF",
        "HALF_TIME",
        "SECOND_HALF",
        "KICKOFF",
        "END_GAME",
        "PARK",
        "GAMEOVER",
    ]
    assert [e.id for e in box.log] == list(range(len(box.log)))
    for before, after in zip(box.log, box.log[1:]):
        assert after.state_pre == before.state, "each entry starts where the previous one ended"
    assert box.log[0].state_pre == RefereeState() and box.log[0].state.stage == "FIRST_HALF"
    assert box.state.score == (1, 0) and box.counts["KICKOFF"] == 3
    summary = box.summary()
    assert summary["score"] == [1, 0]
    assert summary["log"][3] == {"tick": KICKOFF_WAIT + 5, "command": "GOAL", "team": "a", "cause": "goal a"}


def test_frame_carries_the_state():
    box = RefereeBox(CFG)
    cmds = box.step(0, [])
    frame = box.frame(0, cmds)
    assert (frame.stage, frame.command, frame.command_team, frame.score_a, frame.attack_dir_a) == (
        "FIRST_HALF",
        "KICKOFF",
        "a",
        0,
        1,
    )
    assert check_referee(frame) is None


def _frame(**kw) -> Referee:
    return Referee(**{"tick": 5, "stage": "FIRST_HALF", "command": "START", **kw})


@pytest.mark.parametrize(
    ("frame", "problem"),
    [
        (_frame(), None),
        (_frame(commands=[RefCommand(name="THROWIN", team="b", x=1.0, y=4.0)]), None),
        (_frame(command="PARK"), None),
        (_frame(command="CELEBRATE"), "unknown command 'CELEBRATE'"),
        (_frame(stage="OVERTIME"), "unknown stage 'OVERTIME'"),
        (_frame(command_team="c"), "unknown team 'c'"),
        (_frame(commands=[RefCommand(name="KICKOFF", team="c")]), "KICKOFF for unknown team 'c'"),
        (_frame(commands=[RefCommand(name="KICKOFF")]), "KICKOFF without a target team"),
        (_frame(commands=[RefCommand(name="YELLOW_CARD", team="a")]), "YELLOW_CARD without a robot"),
        (_frame(commands=[RefCommand(name="RED_CARD", robot=1)]), "RED_CARD without a target team"),
        (_frame(commands=[RefCommand(name="REPAIR_OUT", team="b", robot=2)]), None),
        (_frame(commands=[RefCommand(name="FREEKICK", team="b", robot=2)]), "FREEKICK with robot 2"),
        (_frame(commands=[RefCommand(name="GAMEOVER")]), None),
        (_frame(commands=[RefCommand(name="DROP_BALL", x=float("nan"))]), "DROP_BALL spot is not finite"),
        (_frame(attack_dir_a=0), "attack_dir_a 0 (expected 1 or -1)"),
    ],
)
def test_check_referee(frame, problem):
    assert check_referee(frame) == problem


@pytest.mark.parametrize("stage", ["PRE_GAME", "FIRST_HALF", "HALF_TIME", "SECOND_HALF", "END_GAME"])
@pytest.mark.parametrize("command", ["START", "THROWIN", "STOP"])
def test_clock_due_no_clock_rule_fires_before_it(stage, command):
    """The box skips a quiet referee tick before `clock_due`: `on_clock` must leave the state as it is there."""
    ticks = [0, 1, 150, 151, HALF - 1, HALF, HALF + 1, END - 1, END, END + 1]
    for start_at, take_by in [(-1, -1), (150, -1), (-1, 150), (HALF + 1, HALF - 1), (END + 5, END + 5)]:
        st = RefereeState(stage=stage, command=command, command_team="a", start_at=start_at, take_by=take_by)
        due = clock_due(st, RULES)
        fired = [t for t in ticks if on_clock(st, t, RULES) != (st, [])]
        assert all(t >= due for t in fired), (start_at, take_by, due, fired)
        assert all(on_clock(st, t, RULES)[0] is st for t in ticks if t < due)


def test_box_skips_quiet_ticks_with_the_same_log():
    """A whole match's clock through `step` (with the skip) logs what `process` tick by tick logs."""
    box, st, log = RefereeBox(CFG), RefereeState(), []  # log: every command `process` issued
    goal = BallEvent(kind="GOAL", tick=KICKOFF_WAIT + 3, team="a", x=6.2)
    for tick in range(0, END + 1, 5):
        events = [goal] if tick == KICKOFF_WAIT + 5 else []
        got = box.step(tick, events)
        want = []
        for change in [Observed(tick, e) for e in events] + [Clock(tick)]:
            st, cmds = process(st, change, RULES)
            want += cmds
        assert got == want, tick
        log += want
    assert box.state == st
    assert [c for e in box.log for c in e.commands] == log
