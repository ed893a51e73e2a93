"""Unit tests of the engine's pymunk world (sim/physics/), real pymunk."""

from __future__ import annotations

import math
import random
from types import SimpleNamespace

import pytest

from arena.config import ROBOTINO, MatchConfig
from arena.schemas.messages import BallEvent, Cmd, RobotState
from arena.sim.drive import Drive
from arena.sim.physics import PIN_TOLERANCE, Physics, wrap_angle

CFG = MatchConfig()
F, R, B = CFG.field, CFG.robot, CFG.ball
DT = CFG.timing.dt
FACE = R.size / 2 + B.radius  # [m] robot centre to a touching ball's centre


def make(robots: int = 1, **kwargs: float) -> Physics:
    """A world with every robot parked side by side in the -y run-off, ball at the centre."""
    ph = Physics(CFG.replace(robots=robots), **kwargs)
    for i, (team, n) in enumerate(ph.robot_ids):
        ph.place_robot(team, n, -5.5 + i, -F.width / 2 - 0.5, 0.0)
    ph.place_ball(0.0, 0.0)
    return ph


def cmd(**kwargs: object) -> Cmd:
    return Cmd(tick=0, **kwargs)


def run(ph: Physics, ticks: int) -> list[BallEvent]:
    events: list[BallEvent] = []
    for _ in range(ticks):
        events.extend(ph.step())
    return events


def ball_in_front(ph: Physics, team: str, n: int, gap: float = 0.01) -> None:
    x, y, th = ph.robot_pose(team, n)
    ph.place_ball(x + (FACE + gap) * math.cos(th), y + (FACE + gap) * math.sin(th))


def kinds(events: list[BallEvent]) -> list[str]:
    return [e.kind for e in events]


# ----------------------------------------------------------------- robots
def test_robot_acceleration_and_speed_are_limited():
    ph = make()
    ph.place_ball(5.0, 3.0)
    ph.place_robot("a", 0, -6.0, -3.5, 0.0)
    ph.set_command("a", 0, cmd(vx=8.0, vy=6.0))  # 10 m/s asked, capped at 5
    prev = (0.0, 0.0)
    for tick in range(1, 136):
        ph.step()
        vx, vy, w = ph.robot_velocity("a", 0)
        v = math.hypot(vx, vy)
        assert v <= R.max_speed + 1e-9, f"tick {tick}: speed {v}"
        accel = math.hypot(vx - prev[0], vy - prev[1]) / DT
        assert accel <= R.max_accel + 1e-6, f"tick {tick}: accel {accel}"
        prev = (vx, vy)
    assert math.hypot(*prev) == pytest.approx(R.max_speed, abs=0.01)
    assert math.atan2(prev[1], prev[0]) == pytest.approx(math.atan2(6.0, 8.0), abs=1e-6)


def test_robot_turn_rate_and_angular_acceleration_are_limited():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ph.set_command("a", 0, cmd(omega=-20.0))
    prev = 0.0
    for tick in range(1, 50):
        ph.step()
        w = ph.robot_velocity("a", 0)[2]
        assert abs(w) <= R.max_omega + 1e-9, f"tick {tick}: omega {w}"
        assert abs(w - prev) <= R.max_alpha * DT + 1e-9, f"tick {tick}: alpha {(w - prev) / DT}"
        prev = w
    assert prev == pytest.approx(-R.max_omega)
    assert ph.robot_pose("a", 0)[:2] == pytest.approx((-3.0, 0.0), abs=1e-9)


def test_body_frame_command_follows_heading():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, math.pi / 2)
    ph.set_command("a", 0, cmd(vx=0.0, vy=-1.0))  # body right = field +x when facing +y
    run(ph, 50)
    vx, vy, _ = ph.robot_velocity("a", 0)
    assert vx == pytest.approx(1.0, abs=1e-6)
    assert vy == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("rp", [R, ROBOTINO], ids=["omni4", "omni3"])
def test_wheel_speed_commands_drive_the_robot_through_forward_kinematics(rp):
    ph = Physics(CFG.replace(robot=rp, robots=1))
    ph.place_robot("a", 0, -3.0, 0.0, math.pi / 2)
    w = Drive(rp).wheel_speeds(0.8, 0.3, 0.0)  # body frame: forward and to the left
    ph.set_command("a", 0, cmd(mode="wheels", wheels=list(w)))
    run(ph, 100)
    vx, vy, omega = ph.robot_velocity("a", 0)
    assert (vx, vy, omega) == pytest.approx((-0.3, 0.8, 0.0), abs=1e-6)  # facing +y: forward is +y


def test_body_and_wheel_commands_obey_the_same_wheel_saturation():
    ph = make(robots=2)
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ph.place_robot("a", 1, -3.0, 2.0, 0.0)
    twist = (-3.5, 3.5, 6.0)  # 4.95 m/s along wheel 1's rolling direction while turning: 124 rad/s asked
    ph.set_command("a", 0, cmd(vx=twist[0], vy=twist[1], omega=twist[2]))
    ph.set_command("a", 1, cmd(mode="wheels", wheels=list(Drive(R).wheel_speeds(*twist))))
    run(ph, 1)
    a0, a1 = ph._robots[0].ctrl, ph._robots[1].ctrl
    assert (*a0.velocity, a0.angular_velocity) == pytest.approx((*a1.velocity, a1.angular_velocity))
    limited = Drive(R).twist(cmd(vx=twist[0], vy=twist[1], omega=twist[2]))
    assert max(abs(x) for x in Drive(R).wheel_speeds(*limited)) == pytest.approx(R.max_wheel_speed)


def test_distance_sums_travel_but_not_placements():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ph.set_command("a", 0, cmd(vx=1.0))
    run(ph, 100)
    x, _, _ = ph.robot_pose("a", 0)
    assert ph.distance[("a", 0)] == pytest.approx(x + 3.0, rel=1e-6)
    ph.place_robot("a", 0, 3.0, 3.0, 0.0)
    ph.set_command("a", 0, cmd())
    run(ph, 10)
    assert ph.distance[("a", 0)] == pytest.approx(x + 3.0, rel=1e-3)
    assert ph.distance[("b", 0)] == 0.0


# ------------------------------------------------------------------- ball
def test_rolling_ball_decelerates_at_rolling_decel_and_stops_cleanly():
    ph = make()
    ph.place_ball(-6.0, 2.0, 3.0, 0.0)
    speeds = []
    for _ in range(400):
        ph.step()
        _, _, _, vx, vy, _ = ph.ball_state()
        speeds.append(math.hypot(vx, vy))
    for a, b in zip(speeds[:300], speeds[1:300]):
        assert (a - b) / DT == pytest.approx(B.rolling_decel, rel=1e-6)
    stop = next(i for i, v in enumerate(speeds) if v == 0.0)
    assert (stop + 1) * DT == pytest.approx(3.0 / B.rolling_decel, abs=2 * DT)
    x, y, *_ = ph.ball_state()
    assert x + 6.0 == pytest.approx(3.0**2 / (2 * B.rolling_decel), abs=0.02)
    run(ph, 50)
    assert ph.ball_state()[:2] == (x, y), "a stopped ball must not creep"


def test_ball_bounces_off_the_fence_with_restitution():
    ph = make()
    fence = F.width / 2 + F.runoff
    ph.place_ball(2.0, fence - 0.5, 0.0, 4.0)
    vys = []
    for _ in range(30):
        ph.step()
        vys.append(ph.ball_state()[4])
        assert ph.ball_state()[1] <= fence - B.radius + 0.01
    before = max(vys)
    after = -min(vys)
    assert after == pytest.approx(B.restitution * before, rel=0.05)


def test_long_random_run_keeps_ball_inside_fence_and_robots_apart():
    rnd = random.Random(7)
    ph = Physics(CFG.replace(robots=3))
    ph.kickoff_positions("a")
    xf, yf = F.length / 2 + F.runoff, F.width / 2 + F.runoff
    ids = ph.robot_ids
    for tick in range(1, 3001):
        if tick % 10 == 1:
            bx, by, *_ = ph.ball_state()
            for team, n in ids:
                x, y, th = ph.robot_pose(team, n)
                if rnd.random() < 0.5:  # chase the ball, in the body frame
                    a = math.atan2(by - y, bx - x) - th
                    c = cmd(vx=4.0 * math.cos(a), vy=4.0 * math.sin(a), omega=3.0 * wrap_angle(a), dribbler=True)
                else:
                    c = cmd(
                        vx=rnd.uniform(-6, 6),
                        vy=rnd.uniform(-6, 6),
                        omega=rnd.uniform(-7, 7),
                        dribbler=rnd.random() < 0.3,
                    )
                if rnd.random() < 0.2:
                    c.kick_speed = rnd.uniform(1.0, 10.0)
                    c.kick_lob = rnd.random() < 0.3
                ph.set_command(team, n, c)
        events = ph.step()
        if any(e.kind == "GOAL" for e in events) or tick % 500 == 0:
            ph.kickoff_positions("b")
        bx, by, bz, *_ = ph.ball_state()
        # discrete collision: a fast ball may dig one substep's travel (< r/2) into the fence
        assert abs(bx) <= xf - B.radius / 2 and abs(by) <= yf - B.radius / 2, f"tick {tick}: ball {bx, by}"
        assert bz >= 0.0
        poses = [ph.robot_pose(t, n) for t, n in ids]
        for i, (x, y, _) in enumerate(poses):
            assert abs(x) <= xf - R.size / 2 + 0.01 and abs(y) <= yf - R.size / 2 + 0.01, f"tick {tick}: robot {ids[i]}"
            for x2, y2, _ in poses[i + 1 :]:
                assert math.hypot(x - x2, y - y2) >= R.size - 0.02, f"tick {tick}: robots overlap"


# ----------------------------------------------------------------- kicker
@pytest.mark.parametrize(("asked", "expected"), [(6.0, 6.0), (20.0, R.kick_max_speed)])
def test_flat_kick_speed_and_direction(asked, expected):
    ph = make()
    ph.place_robot("a", 0, -2.0, 1.0, 0.3)
    ball_in_front(ph, "a", 0, gap=0.05)
    ph.set_command("a", 0, cmd(kick_speed=asked))
    events = ph.step()
    _, _, z, vx, vy, _ = ph.ball_state()
    assert math.hypot(vx, vy) == pytest.approx(expected - B.rolling_decel * DT, abs=1e-6)
    assert math.atan2(vy, vx) == pytest.approx(0.3, abs=1e-9)
    assert z == 0.0
    assert ph.last_toucher() == ("a", 0)
    assert [(e.kind, e.team, e.robot) for e in events] == [("TOUCH", "a", 0)]


def test_kick_needs_the_ball_in_reach_and_fires_once_per_command():
    ph = make()
    ph.place_robot("a", 0, -2.0, 1.0, 0.0)
    ph.place_ball(-2.0 + FACE + 0.3, 1.0)  # too far
    ph.set_command("a", 0, cmd(kick_speed=5.0))
    ph.step()
    assert ph.ball_state()[3] == 0.0
    ph.place_ball(-2.0 + FACE + 0.05, 1.0)  # in reach now: the armed kick fires
    ph.step()
    assert ph.ball_state()[3] > 4.9
    ph.place_ball(-2.0 + FACE + 0.05, 1.0)  # same command: no second kick
    ph.step()
    assert ph.ball_state()[3] == 0.0


def _lob_towards_robot(lob: bool) -> tuple[Physics, float]:
    ph = make()
    ph.place_robot("a", 0, -4.0, 0.0, 0.0)
    ph.place_robot("b", 0, -2.5, 0.0, math.pi)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(kick_speed=8.0, kick_lob=lob))
    ph.step()
    ph.set_command("a", 0, cmd())
    top = 0.0
    for _ in range(150):
        ph.step()
        top = max(top, ph.ball_state()[2])
    return ph, top


def test_lob_flies_over_a_robot_and_lands():
    ph, top = _lob_towards_robot(lob=True)
    v = 8.0 * math.sin(math.radians(45))
    assert top == pytest.approx(v * v / (2 * 9.81), rel=0.02)
    x, _, z, _, _, vz = ph.ball_state()
    assert x > 0.0, "the ball flew past the robot"
    assert (z, vz) == (0.0, 0.0), "the ball landed"
    assert ph.last_toucher() == ("a", 0)
    assert ph.robot_pose("b", 0)[0] == pytest.approx(-2.5, abs=1e-9)


def test_flat_kick_hits_the_robot_in_its_path():
    ph, top = _lob_towards_robot(lob=False)
    assert top == 0.0
    assert ph.ball_state()[0] < -2.5


def test_touch_events_follow_the_ball_from_robot_to_robot():
    ph = make()
    ph.place_robot("a", 0, -4.0, 0.0, 0.0)
    ph.place_robot("b", 0, -2.5, 0.0, math.pi)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(kick_speed=3.0))
    events = run(ph, 100)  # a0 kicks, b0 sends it back, a0 gets it again
    assert [(e.kind, e.team, e.robot) for e in events] == [("TOUCH", "a", 0), ("TOUCH", "b", 0), ("TOUCH", "a", 0)]
    assert ph.last_toucher() == ("a", 0)


# ---------------------------------------------------------------- dribbler
def test_dribbler_carries_the_ball():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0, gap=0.06)
    ph.set_command("a", 0, cmd(vx=1.5, omega=1.0, dribbler=True))
    events = ph.step()
    assert ph.holder() == ("a", 0)
    assert kinds(events) == ["TOUCH"]
    for tick in range(100):
        ph.step()
        x, y, th = ph.robot_pose("a", 0)
        bx, by, *_ = ph.ball_state()
        assert ph.holder() == ("a", 0), f"tick {tick}"
        assert math.hypot(bx - x, by - y) == pytest.approx(FACE + 0.005, abs=0.01)
        assert wrap_angle(math.atan2(by - y, bx - x) - th) == pytest.approx(0.0, abs=0.02)
    assert ph.world(ph.tick).robots[0].has_ball


def test_turning_too_fast_loses_the_ball():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(omega=R.max_omega, dribbler=True))
    lost = None
    for tick in range(50):
        ph.step()
        if ph.holder() is None:
            lost = tick
            break
    assert lost is not None
    assert abs(ph.robot_velocity("a", 0)[2]) > R.dribble_max_omega
    assert abs(ph.robot_velocity("a", 0)[2]) < R.dribble_max_omega + 2 * R.max_alpha * DT


def test_switching_the_dribbler_off_releases_the_ball():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(dribbler=True))
    ph.step()
    assert ph.holder() == ("a", 0)
    ph.set_command("a", 0, cmd(dribbler=False))
    ph.step()
    assert ph.holder() is None


def test_challenger_with_dribbler_releases_the_ball():
    ph = make()
    ph.place_robot("a", 0, 0.0, 0.0, 0.0)
    ph.place_robot("b", 0, 1.2, 0.0, math.pi)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(dribbler=True))
    ph.set_command("b", 0, cmd(vx=0.5, dribbler=True))
    ph.step()
    assert ph.holder() == ("a", 0)
    released = False
    for _ in range(100):
        ph.step()
        if ph.holder() != ("a", 0):
            released = True
            break
    assert released


def test_another_robot_touching_the_held_ball_knocks_it_loose():
    ph = make()
    ph.place_robot("a", 0, 0.0, 0.0, 0.0)
    ph.place_robot("b", 0, 1.5, 0.0, math.pi)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(dribbler=True))
    ph.set_command("b", 0, cmd(vx=1.0))  # no dribbler: only its body challenges
    ph.step()
    assert ph.holder() == ("a", 0)
    events = run(ph, 100)
    assert ("TOUCH", "b", 0) in [(e.kind, e.team, e.robot) for e in events]
    assert ph.holder() is None


def test_a_robot_corner_on_knocks_the_held_ball_loose():
    # a corner reaches size / sqrt(2) from the centre, further than a face
    ph = make()
    ph.place_robot("a", 0, 0.0, 0.0, 0.0)
    ph.place_robot("b", 0, 1.5, 0.0, 1.25 * math.pi)  # a corner leads towards -x
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(dribbler=True))
    ph.set_command("b", 0, cmd(vx=math.sqrt(0.5), vy=-math.sqrt(0.5)))  # field -x, no dribbler
    ph.step()
    assert ph.holder() == ("a", 0)
    events = run(ph, 100)
    assert ("TOUCH", "b", 0) in [(e.kind, e.team, e.robot) for e in events]
    assert ph.holder() is None


@pytest.mark.parametrize("robot", [CFG.robot, ROBOTINO], ids=lambda r: r.model)
def test_the_touch_reach_covers_a_footprint_corner_and_the_ball(robot):
    # the holder's challenge check skips its shape query when no other robot is within `_touch_reach`
    ph = Physics(CFG.replace(robot=robot))
    assert ph._touch_reach > robot.size / math.sqrt(2) + CFG.ball.radius


def test_kick_from_the_dribbler():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(dribbler=True))
    ph.step()
    ph.set_command("a", 0, cmd(dribbler=True, kick_speed=7.0))
    ph.step()
    assert ph.holder() is None
    assert ph.ball_state()[3] == pytest.approx(7.0 - B.rolling_decel * DT, abs=1e-6)


# ----------------------------------------------------------------- events
@pytest.mark.parametrize(("attack_dir_a", "scorer"), [(1, "a"), (-1, "b")])
def test_ball_into_plus_x_goal_scores_once(attack_dir_a, scorer):
    ph = make()
    ph.attack_dir_a = attack_dir_a
    ph.place_ball(4.0, 0.3, 4.0, 0.0)
    events = run(ph, 150)
    goals = [e for e in events if e.kind == "GOAL"]
    assert len(goals) == 1 and goals[0].team == scorer
    assert kinds(events) == ["GOAL"]
    x, y, _, vx, vy, _ = ph.ball_state()
    assert F.length / 2 + B.radius < x < F.length / 2 + F.goal_depth and abs(y) < F.goal_width / 2
    assert (vx, vy) == (0.0, 0.0)
    run(ph, 600)  # no second GOAL, no NO_PROGRESS while the ball waits in the net
    assert kinds(run(ph, 10)) == []


def test_ball_into_minus_x_goal_scores_for_the_other_side():
    ph = make()
    ph.place_ball(-4.0, -0.5, -5.0, 0.0)
    goals = [e for e in run(ph, 100) if e.kind == "GOAL"]
    assert [g.team for g in goals] == ["b"]


def test_ball_over_the_goal_line_beside_the_goal():
    ph = make()
    ph.place_ball(4.0, 2.5, 4.0, 0.0)
    events = run(ph, 100)
    assert kinds(events) == ["GOAL_LINE"]
    assert events[0].x > F.length / 2 + B.radius


def test_high_lob_over_the_crossbar_is_no_goal_and_low_lob_is():
    ph = make()
    ph.place_robot("a", 0, 3.5, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(kick_speed=8.0, kick_lob=True))
    events = ph.step()
    ph.place_robot("a", 0, 0.0, -4.5, 0.0)  # out of the way of the ball coming back off the fence
    events += run(ph, 200)
    assert kinds(events) == ["TOUCH", "GOAL_LINE"]

    ph = make()
    ph.place_robot("a", 0, 4.5, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(kick_speed=4.0, kick_lob=True))
    events = run(ph, 200)
    assert [e.team for e in events if e.kind == "GOAL"] == ["a"]


@pytest.mark.parametrize(("attack_dir_a", "side", "defender"), [(1, 1, "b"), (1, -1, "a"), (-1, 1, "a"), (-1, -1, "b")])
def test_goal_line_event_names_the_defending_team(attack_dir_a, side, defender):
    ph = make()
    ph.attack_dir_a = attack_dir_a
    ph.place_ball(side * 4.0, 2.5, side * 4.0, 0.0)
    events = run(ph, 100)
    assert [(e.kind, e.team) for e in events] == [("GOAL_LINE", defender)]


def test_touch_line_event_names_the_last_toucher():
    ph = make()
    ph.place_robot("a", 0, 0.0, 2.5, math.pi / 2)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(kick_speed=4.0))
    events = run(ph, 100)
    assert kinds(events) == ["TOUCH", "TOUCH_LINE"]
    out = events[1]
    assert (out.last_team, out.last_robot) == ("a", 0)
    assert out.y > F.width / 2 + B.radius
    assert events[0].tick == 1 and out.tick > 1


def test_line_event_rearms_only_after_the_ball_is_back_inside():
    ph = make()
    ph.place_ball(0.0, 3.5, 0.0, 2.0)
    assert kinds(run(ph, 150)) == ["TOUCH_LINE"]  # out, fence bounce, still out
    ph.place_ball(0.0, 3.5, 0.0, 2.0)
    assert kinds(run(ph, 50)) == ["TOUCH_LINE"]


def test_touch_events_on_change_of_toucher_only():
    ph = make()
    ph.place_robot("a", 0, -1.0, 0.0, 0.0)
    ph.place_ball(0.0, 0.0)
    ph.set_command("a", 0, cmd(vx=1.0))
    events = run(ph, 100)  # pushes the ball on and on
    touches = [(e.team, e.robot, e.tick) for e in events if e.kind == "TOUCH"]
    assert len(touches) == 1 and touches[0][:2] == ("a", 0)
    assert events[0].tick == touches[0][2]


def test_no_progress_after_idle_time_once_then_rearmed_by_placement():
    ph = make(no_progress_s=2.0)
    ph.place_ball(1.0, 1.0)
    events = run(ph, 300)
    assert [(e.kind, e.tick) for e in events] == [("NO_PROGRESS", 100)]
    ph.place_ball(1.0, 1.0)
    events = run(ph, 100)
    assert [(e.kind, e.tick) for e in events] == [("NO_PROGRESS", 400)]
    assert Physics(CFG).no_progress_s == 10.0


def test_no_progress_rearms_when_the_ball_moves_again():
    ph = make(no_progress_s=1.0)
    ph.place_robot("a", 0, -1.0, 0.0, 0.0)
    events = run(ph, 60)
    assert kinds(events) == ["NO_PROGRESS"]
    ph.set_command("a", 0, cmd(vx=1.0))
    run(ph, 50)
    ph.set_command("a", 0, cmd(vx=-1.0))  # the robot pushes the ball on and leaves it rolling
    events = run(ph, 400)
    assert set(kinds(events)) == {"NO_PROGRESS"}
    assert events[-1].x > 1.0, "re-armed once the ball had left its first circle"
    assert ph.ball_state()[3:5] == (0.0, 0.0)


def test_a_ball_creeping_within_the_progress_radius_makes_no_progress():
    ph = make(no_progress_s=2.0)
    ph.place_ball(1.0, 1.0, 0.5, 0.0)  # rolls 0.31 m: less than the progress radius
    events = run(ph, 120)
    assert [(e.kind, e.tick) for e in events] == [("NO_PROGRESS", 100)]
    assert CFG.rules.progress_radius == 0.5


# --------------------------------------------------------------- placement
@pytest.mark.parametrize("robots", [1, 2, 3, 4, 5, 6])
@pytest.mark.parametrize("attack_dir_a", [1, -1])
@pytest.mark.parametrize("kicking", ["a", "b"])
def test_kickoff_positions(robots, attack_dir_a, kicking):
    ph = Physics(CFG.replace(robots=robots))
    ph.attack_dir_a = attack_dir_a
    ph.kickoff_positions(kicking)
    assert ph.ball_state() == (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    poses = {}
    for team, n in ph.robot_ids:
        attack = attack_dir_a if team == "a" else -attack_dir_a
        x, y, th = ph.robot_pose(team, n)
        poses[(team, n)] = (x, y)
        assert x * attack < 0, f"{team}/{n} not in its own half"
        assert abs(x) <= F.length / 2 - R.size / 2 + 1e-9 and abs(y) <= F.width / 2 - R.size / 2
        assert math.cos(th) == pytest.approx(attack)
        if n == 0:
            assert (abs(x), y) == (pytest.approx(F.length / 2 - R.size / 2), 0.0)
        elif n == 1 and team == kicking:
            assert (x, y) == (pytest.approx(-0.5 * attack), 0.0)
        else:
            assert math.hypot(x, y) >= F.center_circle_radius + R.size / 2
    pts = list(poses.values())
    for i, (x, y) in enumerate(pts):
        for x2, y2 in pts[i + 1 :]:
            assert math.hypot(x - x2, y - y2) > R.size * 1.5


# ------------------------------------------------------------ determinism
def test_two_instances_with_the_same_commands_agree_at_every_tick():
    cfg = CFG.replace(robots=3)
    worlds = [Physics(cfg), Physics(cfg)]
    for ph in worlds:
        ph.kickoff_positions("a")
    rnd = random.Random(3)
    ids = worlds[0].robot_ids
    for tick in range(1, 801):
        if tick % 5 == 1:
            cmds = {
                r: cmd(
                    vx=rnd.uniform(-5, 5),
                    vy=rnd.uniform(-5, 5),
                    omega=rnd.uniform(-6, 6),
                    dribbler=rnd.random() < 0.5,
                    kick_speed=rnd.choice([0.0, 0.0, 0.0, 6.0]),
                    kick_lob=rnd.random() < 0.5,
                )
                for r in ids
            }
            for ph in worlds:
                for (team, n), c in cmds.items():
                    ph.set_command(team, n, c)
        ev = [ph.step() for ph in worlds]
        assert ev[0] == ev[1], f"events differ at tick {tick}"
        assert worlds[0].world(tick) == worlds[1].world(tick), f"world differs at tick {tick}"
    assert worlds[0].distance == worlds[1].distance


def _random_play(cfg: MatchConfig, ticks: int) -> list[tuple[list[BallEvent], object, dict]]:
    """Events, world frame and distances at every tick of a match of random commands (contacts, kicks, dribbles)."""
    ph = Physics(cfg)
    ph.kickoff_positions("a")
    rnd = random.Random(5)
    out = []
    for tick in range(1, ticks + 1):
        if tick % 4 == 1:
            for team, n in ph.robot_ids:
                ph.set_command(
                    team,
                    n,
                    cmd(
                        vx=rnd.uniform(-5, 5),
                        vy=rnd.uniform(-5, 5),
                        omega=rnd.uniform(-6, 6),
                        dribbler=rnd.random() < 0.5,
                        kick_speed=rnd.choice([0.0, 0.0, 6.0]),
                        kick_lob=rnd.random() < 0.3,
                    ),
                )
        out.append((ph.step(), ph.world(tick), ph.distance))
    return out


def test_the_direct_chipmunk_calls_give_what_pymunks_api_gives(monkeypatch):
    """`step_space`, `BodyReader` and `ControlWriter` (sim/physics/bodies.py) bit for bit.

    The distances too: summed here after every substep, robot after robot, as `Physics.step` once did."""
    from pymunk import batch as pmbatch

    from arena.sim.physics import bodies, model, world

    cfg = CFG.replace(robots=3)
    fast = _random_play(cfg, 600)

    # The same world again, every direct call replaced by pymunk's public API.
    spaces, ctrls = {}, {}  # C pointer -> pymunk object
    walked: dict[tuple[str, int], list[float]] = {}  # robot -> [x, y, metres] after each substep
    real_build = world.WorldBuilding._build_world

    def build(self, *args):
        real_build(self, *args)
        spaces[self._space._space] = self._space
        ctrls.update((r.ctrl._body, r.ctrl) for r in self._robots)
        robots.extend(self._robots)

    robots: list = []

    def step_space(space_c, h) -> None:
        for r in robots:
            walked.setdefault((r.team, r.n), [*r.body.position, 0.0])
        spaces[space_c].step(h)
        for r in robots:
            w, (x, y) = walked[(r.team, r.n)], r.body.position
            w[:] = x, y, w[2] + math.hypot(x - w[0], y - w[1])

    class Read:
        """BodyReader's call, and the parts of it that `Physics.step` inlines, over pymunk's public batch API."""

        def __init__(self, space: object, fields: pmbatch.BodyFields = bodies._ALL_FIELDS) -> None:
            self._space, self._iterate, self._data, self._fields = space._space, None, None, fields
            self._arr = SimpleNamespace(arr=self, num=0)  # `unpack(arr.arr, arr.num)` gets this reader back
            self.last: list[float] = []

        def _each(self, space_c, _iterate, _data) -> None:
            buf = pmbatch.Buffer()
            pmbatch.get_space_bodies(spaces[space_c], self._fields, buf)
            read = memoryview(buf.float_buf()).cast("d").tolist()
            self.last = self.last + read if self._arr.num else read  # appended, as a C array's pushes are
            self._arr.num = len(self.last)

        def __call__(self) -> list[float]:
            self._arr.num = 0
            self._each(self._space, None, None)
            return self.last

    class Control:
        """ControlWriter's call over pymunk's public API: robot i's control body gets values[3i:3i + 3]."""

        def __init__(self, space: object) -> None:
            self.space = space

        def __call__(self, values: list[float]) -> None:
            mine = [r for r in robots if r.ctrl.space is self.space]
            assert len(values) == 3 * len(mine)
            for i, r in enumerate(mine):
                r.ctrl.velocity = values[3 * i], values[3 * i + 1]
                r.ctrl.angular_velocity = values[3 * i + 2]
                written.add(r.ctrl._body)

    written: set = set()
    monkeypatch.setattr(world.WorldBuilding, "_build_world", build)
    monkeypatch.setattr(world, "BodyReader", Read)
    monkeypatch.setattr(model, "unpack", lambda reader, _num: reader.last)
    monkeypatch.setattr(model, "step_space", step_space)
    monkeypatch.setattr(world, "ControlWriter", Control)
    public = _random_play(cfg, 600)

    assert spaces and ctrls and written == set(ctrls), "the public API was not used"
    assert sum(len(events) for events, _, _ in fast) > 0, "nothing happened to the ball"
    assert len({(w.ball_x, w.ball_y) for _, w, _ in fast}) > 100, "the ball hardly moved"
    for tick, (a, b) in enumerate(zip(fast, public, strict=True), start=1):
        assert a == b, f"tick {tick} differs"
    assert min(fast[-1][2].values()) > 1.0, "the robots hardly moved"
    assert fast[-1][2] == {r: w[2] for r, w in walked.items()}


def test_world_message_is_ground_truth():
    ph = make()
    ph.place_robot("b", 0, 1.0, 2.0, 3.0)
    w = ph.world(7)
    assert (w.tick, w.t) == (7, pytest.approx(7 * DT))
    b0 = next(r for r in w.robots if (r.team, r.robot) == ("b", 0))
    assert (b0.x, b0.y, b0.theta) == (1.0, 2.0, 3.0)
    assert (w.ball_x, w.ball_y, w.last_team, w.last_robot) == (0.0, 0.0, "", -1)


def test_wrap_angle():
    assert wrap_angle(math.pi) == math.pi
    assert wrap_angle(-math.pi) == math.pi
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-7.0) == pytest.approx(-7.0 + math.tau)


# ------------------------------------------------------------------ fouls
def _charge(speed: float, teams: tuple[str, str] = ("a", "b")) -> list[BallEvent]:
    """Robot 1 of teams[0] drives at `speed` [m/s] into robot 1 of teams[1], which stands still."""
    ph = make(robots=2)
    ph.place_ball(0.0, -3.0)
    ph.place_robot(teams[0], 1, -2.0, 1.0, 0.0)
    ph.place_robot(teams[1], 1 if teams[1] != teams[0] else 0, 0.0, 1.0, math.pi)
    ph.set_command(teams[0], 1, cmd(vx=speed))
    return run(ph, 150)


def test_driving_into_an_opponent_fast_is_pushing():
    events = _charge(3.0)
    fouls = [e for e in events if e.kind == "FOUL_PUSHING"]
    assert len(fouls) == 1
    foul = fouls[0]
    assert (foul.team, foul.robot) == ("a", 1)
    assert foul.x == pytest.approx(-0.225, abs=0.05) and foul.y == pytest.approx(1.0, abs=0.25)


@pytest.mark.parametrize(("speed", "teams"), [(1.0, ("a", "b")), (3.0, ("a", "a"))], ids=["gentle", "teammate"])
def test_slow_contact_or_a_teammate_is_no_foul(speed, teams):
    assert "FOUL_PUSHING" not in kinds(_charge(speed, teams))


def test_the_robot_that_drove_in_is_the_offender():
    ph = make(robots=2)
    ph.place_ball(0.0, -3.0)
    ph.place_robot("a", 1, -2.0, 1.0, 0.0)
    ph.place_robot("b", 1, 1.0, 1.0, math.pi)
    ph.set_command("a", 1, cmd(vx=0.5))
    ph.set_command("b", 1, cmd(vx=2.5))  # b drives (forward = -x) much faster into a
    fouls = [e for e in run(ph, 150) if e.kind == "FOUL_PUSHING"]
    assert [(e.team, e.robot) for e in fouls] == [("b", 1)]


def test_dribbling_further_than_three_metres_is_a_foul_once():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(vx=1.5, dribbler=True))
    events = run(ph, 200)
    fouls = [e for e in events if e.kind == "FOUL_DRIBBLING"]
    assert len(fouls) == 1 and (fouls[0].team, fouls[0].robot) == ("a", 0)
    assert fouls[0].x - FACE == pytest.approx(-3.0 + CFG.rules.dribble_limit, abs=0.05)
    assert ph.holder() == ("a", 0), "the engine reports; the referee stops play"


def test_letting_go_starts_a_new_possession():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(vx=1.5, dribbler=True))
    events = run(ph, 100)  # 2.4 m
    ph.set_command("a", 0, cmd(vx=1.5))
    events += run(ph, 2)
    ph.set_command("a", 0, cmd(vx=1.5, dribbler=True))
    events += run(ph, 60)
    assert "FOUL_DRIBBLING" not in kinds(events)


# ------------------------------------------------------- play and stoppages
def test_while_play_is_stopped_the_pinned_ball_stays_and_nothing_is_reported():
    ph = make(no_progress_s=0.5)
    ph.stop_play()
    ph.pin_ball(1.0, 0.0)
    ph.place_robot("a", 0, -1.0, 0.0, 0.0)
    ph.set_command("a", 0, cmd(vx=2.0, dribbler=True, kick_speed=6.0))  # runs into the ball, tries to kick
    events = run(ph, 150)
    assert events == []
    assert ph.ball_state()[:2] == pytest.approx((1.0, 0.0), abs=PIN_TOLERANCE)
    assert ph.holder() is None and ph.last_toucher() is None


def test_after_start_the_first_touch_is_reported_even_by_the_last_toucher():
    ph = make()
    ph.place_robot("a", 0, -3.0, 0.0, 0.0)
    ball_in_front(ph, "a", 0)
    ph.set_command("a", 0, cmd(kick_speed=1.0))
    assert kinds(ph.step()) == ["TOUCH"]
    ph.stop_play()
    ph.pin_ball(0.0, 0.0)
    ph.place_robot("a", 0, -FACE - 0.3, 0.0, 0.0)
    ph.set_command("a", 0, cmd())
    run(ph, 10)
    ph.start_play()
    ph.set_command("a", 0, cmd(vx=1.0))
    events = run(ph, 50)
    assert [(e.kind, e.team, e.robot) for e in events] == [("TOUCH", "a", 0)]


def test_robot_states_are_built_once_per_snapshot_and_follow_every_change():
    ph = make()
    first = ph.robot_states()
    assert ph.robot_states() is first, "read twice from one snapshot, built once"
    ph.place_robot("b", 0, 1.0, 2.0, 3.0)
    placed = ph.robot_states()
    assert placed is not first and ("b", 0, 1.0, 2.0, 3.0) == next(st for st in placed if st[:2] == ("b", 0))[:5]
    ph.set_command("b", 0, cmd(vx=1.0))
    ph.step()
    moved = next(st for st in ph.robot_states() if st[:2] == ("b", 0))
    assert moved[2] != 1.0 and ph.world(1).robots == [
        RobotState(team=t, robot=n, x=x, y=y, theta=th, vx=vx, vy=vy, omega=w, has_ball=False)
        for t, n, x, y, th, vx, vy, w in ph.robot_states()
    ]
