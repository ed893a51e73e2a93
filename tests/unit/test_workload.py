"""recording/analysis/workload.py: each metre attributed to team mode, Fig. 5 area and activity;
pushing fouls at their impact; send-offs."""

from __future__ import annotations

import pytest

from arena.config import MatchConfig
from arena.recording.analysis import workload
from arena.schemas.messages import Referee, RobotState, World

CFG = MatchConfig(robots=2)
DT = CFG.timing.dt
START = {0: Referee(tick=0, stage="FIRST_HALF", command="START", attack_dir_a=1)}


def frames(me: list[tuple[float, float]], ball: tuple[float, float], b1=(5.0, 3.5), b_holds=False) -> list[World]:
    """Robot a/1 through the points `me` (one per tick, velocity from the next step), b/1 still at `b1`."""
    out = []
    for k, (x, y) in enumerate(me):
        nx, ny = me[min(k + 1, len(me) - 1)]
        robots = [
            RobotState(team="a", robot=1, x=x, y=y, theta=0.0, vx=(nx - x) / DT, vy=(ny - y) / DT),
            RobotState(team="b", robot=1, x=b1[0], y=b1[1], theta=0.0, has_ball=b_holds),
        ]
        out.append(World(tick=k, t=k * DT, ball_x=ball[0], ball_y=ball[1], robots=robots))
    return out


def line(start: tuple[float, float], step: tuple[float, float], n: int = 11) -> list[tuple[float, float]]:
    return [(start[0] + k * step[0], start[1] + k * step[1]) for k in range(n)]


@pytest.mark.parametrize(
    "me, ball, b_holds, cell",
    [
        # team a attacks +x: its own goal centre is (-6, 0)
        (line((-2.0, 2.0), (-0.04, 0.0)), (3.0, -3.0), True, "defending/defence/returning"),
        (line((-3.0, 0.0), (0.0, 0.04)), (0.0, 0.0), True, "defending/defence/blocking"),  # on the ball's line to goal
        (line((2.0, 2.0), (0.0, -0.04)), (2.0, -1.0), False, "loose/attack/chasing"),
        (line((0.0, 2.0), (0.04, 0.0)), (0.0, -3.0), True, "defending/overlap/advancing"),
    ],
)
def test_every_metre_goes_to_one_mode_area_and_activity(me, ball, b_holds, cell):
    b1 = (ball[0] + 0.3, ball[1]) if b_holds else (5.0, 3.5)
    row = workload.metres(CFG, frames(me, ball, b1, b_holds), START)["a/1"]
    assert row["total"] == pytest.approx(0.4, abs=1e-6)
    assert row[cell] == pytest.approx(0.4, abs=1e-6), row


def test_the_possession_of_the_last_holder_stays_while_the_ball_is_loose():
    worlds = frames(line((-2.0, 2.0), (-0.04, 0.0)), (3.0, -3.0), (3.3, -3.0), b_holds=True)
    worlds[5:] = [
        World(
            tick=w.tick,
            t=w.t,
            ball_x=1.0,
            ball_y=-3.0,
            robots=[w.robots[0], w.robots[1].__class__(team="b", robot=1, x=5.0, y=3.5, theta=0.0)],
        )
        for w in worlds[5:]
    ]
    row = workload.metres(CFG, worlds, START)["a/1"]
    assert set(row) == {"total", "defending/defence/returning"}


def test_stopped_play_and_placements():
    me = line((-2.0, 2.0), (-0.04, 0.0))
    me[6] = (4.0, 0.0)  # placed by the engine: no travel
    me[7:] = line((4.0, 0.0), (-0.04, 0.0), 4)
    stop = {0: Referee(tick=0, stage="FIRST_HALF", command="STOP", attack_dir_a=1)}
    row = workload.metres(CFG, frames(me, (0.0, 3.0)), stop)["a/1"]
    assert row["total"] == pytest.approx(0.32, abs=1e-6)
    assert all(cell.startswith("stopped/") for cell in row if cell != "total")
    assert workload.marginal(row, 1) == pytest.approx({"defence": 0.2, "attack": 0.12})


def test_a_pushing_foul_at_its_impact_and_the_send_off_it_earns():
    # a/1 drives at 2 m/s into b/1 standing at x = 0.5; they touch (0.45 m squares) from x = 0.05 on
    me = line((-0.3, 0.0), (0.04, 0.0), 12)
    worlds = frames(me, (3.0, 3.0), b1=(0.5, 0.0))
    log = [
        {"tick": 9, "command": "STOP", "team": "", "cause": "foul_pushing a/1"},
        {"tick": 9, "command": "FREEKICK", "team": "b", "cause": "foul_pushing a/1"},
        {"tick": 9, "command": "DOUBLE_YELLOW", "team": "a", "robot": 1, "cause": "foul_pushing a/1"},
        {"tick": 2, "command": "GOAL", "team": "b", "cause": "goal b"},
    ]
    (foul,) = workload.fouls(CFG, worlds, START, {"log": log})
    assert foul["victim"] == "b/1" and foul["latency_ms"] == CFG.timing.perception_latency * DT * 1000
    assert foul["offender_speed"] == pytest.approx(2.0) and foul["victim_speed"] == 0.0
    assert foul["unseen_closing_m"] == pytest.approx(0.04 * CFG.timing.perception_latency)
    assert foul["activity"] == "advancing"
    (off,) = workload.send_offs({"log": log})
    assert off == {
        "tick": 9,
        "card": "DOUBLE_YELLOW",
        "team": "a",
        "robot": 1,
        "score_then": [0, 1],
        "cause": "foul_pushing a/1",
        "foul_ticks": [9],
    }
