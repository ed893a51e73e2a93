"""A ball put down out of play is called; teleports that land on a robot; robots driven by a step.

docs/rules.md rules 10-13 for a ball at rest beyond a line, rule 22 for the
penalty's placement; sim/director.py for `safely`, `roll`, unstacking and
`ControlRobot` (docs/scenarios.md)."""

from __future__ import annotations

import math

import msgspec
import pytest

from arena.config import MatchConfig, ScenarioParams
from arena.match.inprocess import play_in_process
from arena.rules.setpieces import penalty_positions
from arena.scenarios import ScenarioError, load, run_one
from arena.schemas.messages import ControlRobot, Referee, RefereeOverride, Step, TeleportBall, TeleportRobot, World

HEAD = '[[scenario]]\nname = "{name}"\ntime_limit = {limit}\n[scenario.play]\nrobots = 2\n'


def scenario(tmp_path, body: str, name: str = "s", limit: float = 2.0):
    path = tmp_path / f"{name}.scenario.toml"
    path.write_text(HEAD.format(name=name, limit=limit) + body)
    return load(path)


def expect_command(command: str, team: str = "", within: float = 0.5, start: float = 0.0) -> str:
    team_line = f'team = "{team}"\n' if team else ""
    return (
        f'[[scenario.expect]]\nname = "call"\nkind = "command"\ncommand = "{command}"\n{team_line}'
        f"from = {start}\nwithin = {within}\n"
    )


# ------------------------------------------------- a ball at rest beyond a line
@pytest.mark.parametrize(
    ("ball", "command", "team"),
    [
        ("x = 6.5, y = 0.0", "GOALKICK", "b"),  # in b's goal, nobody touched it: no goal, a goal kick
        ("x = 6.6, y = -2.5", "GOALKICK", "b"),  # behind b's goal line beside the goal
        ("x = -6.6, y = 3.0", "GOALKICK", "a"),  # behind a's goal line
        ("x = 2.0, y = 4.6", "DROP_BALL", ""),  # beyond a touch line, nobody touched it (rule 11)
        ("x = -3.0, y = -4.7", "DROP_BALL", ""),
    ],
)
def test_a_ball_put_at_rest_beyond_a_line_gets_the_referees_decision(tmp_path, ball, command, team):
    body = f"[scenario.start]\nball = {{ {ball}, vx = 0.0, vy = 0.0 }}\n" + expect_command(command, team)
    v = run_one(scenario(tmp_path, body), 0)
    assert v.passed, v.failures


def test_a_ball_teleported_out_after_a_touch_gives_the_restart_the_last_touch_dictates(tmp_path):
    """b/1 (driven still by a control step) touches the ball, which a step then puts behind b's goal line:
    a corner for a; put beyond a touch line instead, a throw-in for a."""
    start = (
        "[scenario.start]\nball = { x = 4.0, y = 2.0, vx = 2.0, vy = 0.0 }\n"
        'robots = [{ robot = "b/1", x = 4.8, y = 2.0, theta = 3.14 }]\n'
        '[[scenario.step]]\nat = 0.0\ncontrol = [{ robot = "b/1", seconds = 3.0 }]\n'
    )
    touched = '[[scenario.expect]]\nname = "b touched"\nkind = "last_touch"\nteam = "b"\nuntil = 0.9\n'
    corner = start + "[[scenario.step]]\nat = 1.0\nball = { x = 6.6, y = 2.5, vx = 0.0, vy = 0.0 }\n"
    v = run_one(scenario(tmp_path, corner + touched + expect_command("CORNER", "a", 1.5, 1.0), limit=3.0), 0)
    assert v.passed, v.failures
    throw = start + "[[scenario.step]]\nat = 1.0\nball = { x = 3.0, y = 4.7, vx = 0.0, vy = 0.0 }\n"
    v = run_one(scenario(tmp_path, throw + touched + expect_command("THROWIN", "a", 1.5, 1.0), limit=3.0), 0)
    assert v.passed, v.failures


def commands(steps, ticks=100):
    cfg = MatchConfig(seed=1, robots=2, scenario=ScenarioParams(ticks=ticks, stage="FIRST_HALF", steps=steps))
    _, frames = play_in_process(cfg, watch=("referee",))
    refs = [msgspec.msgpack.decode(p, type=Referee) for p in frames["referee"]]
    return [(c.name, c.team, c.tick) for r in refs for c in r.commands]


def test_a_ball_beyond_the_fence_is_refused_at_load_and_at_run_time(tmp_path):
    with pytest.raises(ScenarioError, match=r"start\.ball\.x: a number in \[-6\.89, 6\.89\] m \(inside the fence\)"):
        scenario(tmp_path, "[scenario.start]\nball = { x = 50.0, y = 0.0 }\n")
    # a configuration not made by the loader: the engine's range check refuses the step (the ball stays in play)
    steps = (Step(at=0, actions=[RefereeOverride(command="START")]), Step(at=10, actions=[TeleportBall(x=50.0, y=0.0)]))
    got = commands(steps)
    assert not any(n == "GOALKICK" and 10 <= k <= 20 for n, t, k in got), got


def test_the_penalty_placement_keeps_every_robot_inside_the_field_of_play():
    """Rule 22: a defender beside the area was put at (6.13, 2.84), behind its own goal line."""
    cfg = MatchConfig(robots=3)
    robots = [("a", 0, -5.8, 0.0), ("a", 1, 3.0, 0.0), ("b", 0, 5.8, 0.0), ("b", 1, 5.5, 2.0), ("b", 2, 5.6, -1.5)]
    moves = penalty_positions(robots, "a", (4.0, 0.0), 1, cfg)
    f = cfg.field
    for t, n, x, y, _ in moves:
        assert abs(x) <= f.length / 2 and abs(y) <= f.width / 2, (t, n, x, y)
        if (t, n) not in (("a", 1), ("b", 0)):
            assert math.hypot(x - 4.0, y) >= cfg.rules.setpiece_distance, (t, n, x, y)
            assert not (x > 4.5 - 0.32 and abs(y) < 2.5 + 0.32), f"{t}/{n} still in the penalty area"


# ------------------------------------------------------------------ teleports
def worlds_of(steps, ticks=60):
    cfg = MatchConfig(
        seed=2, home="BS", away="BS", scenario=ScenarioParams(ticks=ticks, stage="FIRST_HALF", steps=steps)
    )
    summaries, frames = play_in_process(cfg, watch=("world",))
    return summaries, [msgspec.msgpack.decode(p, type=World) for p in frames["world"]]


def pose(w: World, team: str, n: int) -> tuple[float, float]:
    r = next(r for r in w.robots if (r.team, r.robot) == (team, n))
    return r.x, r.y


def test_two_robots_teleported_onto_one_spot_are_apart_at_once():
    """They took 0.4 s to come 0.40 m apart; now the second goes to the nearest free spot in the same tick."""
    steps = (
        Step(at=0, actions=[RefereeOverride(command="STOP")]),
        Step(
            at=5,
            actions=[TeleportRobot(team="a", robot=1, x=1.0, y=1.0), TeleportRobot(team="b", robot=1, x=1.0, y=1.0)],
        ),
    )
    summaries, worlds = worlds_of(steps, ticks=10)
    w = next(w for w in worlds if w.tick == 5)
    (ax, ay), (bx, by) = pose(w, "a", 1), pose(w, "b", 1)
    assert (ax, ay) == (1.0, 1.0), "the first lands where it was sent"
    assert math.hypot(ax - bx, ay - by) >= 0.45 * math.sqrt(2), (bx, by)
    assert math.hypot(bx - 1.0, by - 1.0) < 0.75, "the nearest free spot, not far away"
    assert summaries["engine"].extra["teleports_moved"] == [{"tick": 5, "robot": "b/1", "x": bx, "y": by}]


def test_safely_moves_a_teleport_to_the_nearest_free_spot_and_roll_keeps_the_ball_on_the_ground():
    steps = (
        Step(at=0, actions=[RefereeOverride(command="STOP"), TeleportBall(x=2.0, y=0.0, vx=0.0, vy=0.0)]),
        Step(at=3, actions=[TeleportRobot(team="a", robot=2, x=2.0, y=0.0, safely=True)]),  # onto the ball
        Step(at=6, actions=[TeleportBall(x=-3.0, y=1.0, safely=True)]),  # clear already: exactly there
        Step(at=9, actions=[TeleportBall(x=0.0, y=-2.0, z=0.5, vz=1.0, vx=1.0, vy=0.0, roll=True)]),
    )
    _, worlds = worlds_of(steps, ticks=12)
    at = {w.tick: w for w in worlds}
    x, y = pose(at[3], "a", 2)
    assert math.hypot(x - 2.0, y) >= 0.45 * math.sqrt(0.5) + 0.11, "clear of the ball"
    assert math.hypot(x - 2.0, y) < 0.6
    assert (at[6].ball_x, at[6].ball_y) == (-3.0, 1.0)
    assert at[9].ball_z == 0.0 and at[9].ball_vz == 0.0 and at[9].ball_vx == 1.0, "rolling, not flying"
    _, unsafe = worlds_of(steps[:2] + (Step(at=3, actions=[TeleportRobot(team="a", robot=2, x=2.0, y=0.0)]),), 4)
    assert pose(next(w for w in unsafe if w.tick == 3), "a", 2) == (2.0, 0.0), "without safely: where it is sent"


def test_a_control_step_drives_a_robot_with_body_frame_velocities_for_its_time():
    """SSL RobotControl: b/1 (whose strategy would do something else) drives 1 m/s forward, facing +y."""
    steps = (
        Step(
            at=0,
            actions=[
                RefereeOverride(command="START"),
                TeleportRobot(team="b", robot=1, x=0.0, y=-2.0, orientation=math.pi / 2),
            ],
        ),
        Step(at=5, actions=[ControlRobot(team="b", robot=1, ticks=100, vx=1.0)]),
    )
    _, worlds = worlds_of(steps, ticks=160)
    at = {w.tick: w for w in worlds}
    x0, y0 = pose(at[5], "b", 1)
    x1, y1 = pose(at[105], "b", 1)
    # 2 m/s^2 to 1 m/s takes 0.5 s: 0.25 m, then 1.5 s at 1 m/s (a tick of actuation delay)
    assert abs(x1 - x0) < 0.05 and 1.6 < y1 - y0 < 1.8, (x0, y0, x1, y1)
    r = next(r for r in at[104].robots if (r.team, r.robot) == ("b", 1))
    assert abs(r.vy - 1.0) < 0.05, r
