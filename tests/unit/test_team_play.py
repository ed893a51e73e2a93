"""Team play (issue 4): the advance attack and defense skills of paper 2 (Fig. 7), the ball
handling every strategy shares, the robot brain's reactions in set situations, and the
physics rule that keeps two robots from swapping the ball every tick."""

from __future__ import annotations

import math
import random

import pytest

from arena.config import MatchConfig
from arena.navigation.frames import wrap_angle
from arena.schemas.messages import BallSeen, Cmd, Order, Pose, RobotSeen, Sense, TeamPose
from arena.sim.physics import NO_CHALLENGE_S, Physics
from arena.strategies import registry
from arena.strategies import roles as R
from arena.strategies import skills as S
from arena.strategies.base import RobotContext

CFG = MatchConfig()
CHALLENGE = CFG.robot.size / 2 + CFG.ball.radius + 0.20  # [m] physics: a dribbler this close to the ball challenges
REACH = CFG.robot.size / 2 + CFG.ball.radius  # [m] robot centre to a held ball


# ------------------------------------------------------------------ skills
def test_circle_past_heads_for_the_side_away_from_the_near_touch_line_while_far():
    pos, opp, goal = (0.0, 1.0), (2.0, 1.0), (6.0, 0.0)  # we are on the left (y > 0)
    way, heading, rot = S.circle_past(pos, opp, goal, 1.0)
    assert way[1] < opp[1] - 0.9  # beside it, on the right: towards the middle (paper 2)
    assert heading == pytest.approx(S.angle_to(pos, goal))  # still facing the goal
    assert rot == 1.0


def test_circle_past_goes_round_with_the_body_between_opponent_and_ball():
    opp, goal = (2.0, 1.0), (6.0, 0.0)
    pos = (1.3, 0.6)  # close behind it, on the right
    way, heading, rot = S.circle_past(pos, opp, goal, 1.0)
    before, after = S.angle_to(opp, pos), S.angle_to(opp, way)
    assert wrap_angle(after - before) * rot > 0.5  # the waypoint is further round the opponent
    assert S.dist(way, opp) == pytest.approx(1.0)
    ball = (pos[0] + REACH * math.cos(heading), pos[1] + REACH * math.sin(heading))
    assert S.dist(ball, opp) > CHALLENGE  # side-on: the held ball is out of the opponent's reach
    # the way round is kept once chosen, even from the other side of the decision line
    _, _, again = S.circle_past((1.2, 1.4), opp, goal, 1.0, rot=rot)
    assert again == rot


def test_circle_past_heads_for_the_goal_once_round():
    opp, goal = (2.0, 1.0), (6.0, 0.0)
    pos = (2.9, 0.7)  # past it
    way, heading, _ = S.circle_past(pos, opp, goal, 1.0, rot=1.0)
    assert heading == pytest.approx(S.angle_to(pos, goal))
    assert S.angle_to(opp, way) == pytest.approx(S.angle_to(opp, goal))


def test_best_aim_with_a_heading_prefers_a_clear_aim_that_needs_less_turn():
    keeper = [(5.65, 0.0)]
    free, clear = S.best_aim((2.0, 0.0), 6.0, 1.0, keeper, 0.36)
    assert clear and abs(free[1]) > 0.5  # most room: a corner
    left, _ = S.best_aim((2.0, 0.0), 6.0, 1.0, keeper, 0.36, heading=0.2)
    right, _ = S.best_aim((2.0, 0.0), 6.0, 1.0, keeper, 0.36, heading=-0.2)
    assert left[1] > 0.5 and right[1] < -0.5  # the corner it already faces
    blocked, clear = S.best_aim((2.0, 0.0), 6.0, 1.0, [(2.8, 0.0)], 0.36, heading=0.0)
    assert not clear  # a defender 0.8 m ahead blocks every aim point


def test_aside_point_is_square_to_the_line_to_our_goal_on_our_side():
    ball, own = (0.0, 0.0), (-6.0, 0.0)
    assert S.aside_point(ball, own, (0.3, 0.4), 0.9) == pytest.approx((0.0, 0.9))
    assert S.aside_point(ball, own, (0.3, -0.4), 0.9) == pytest.approx((0.0, -0.9))


def test_mark_point_is_goal_side_of_the_marked_opponent():
    assert S.mark_point((-3.0, 0.0), (-6.0, 0.0), 0.8) == pytest.approx((-3.8, 0.0))


def test_open_point_prefers_clear_pass_and_shot_lines():
    ball = (0.0, 0.0)
    opponents = [(1.5, 0.0), (5.65, 0.0)]  # a defender straight ahead, the keeper
    got = S.open_point(ball, [(3.0, 0.0), (3.0, 1.5)], opponents, 6.0, 1.0, 0.36)
    assert got == (3.0, 1.5)


# ------------------------------------------------------------ robot brain
def _robot(name: str, n: int = 1):
    return registry.get(name).make_robot(RobotContext(cfg=CFG, team="a", n=n, rng=random.Random(0)))


def _order(tick: int, n: int, role: str, state: int, **kw) -> Order:
    return Order(tick=tick, robot=n, command="START", command_team="a", attack_dir=1, role=role, role_state=state, **kw)


def _body_to_field(c: Cmd, theta: float) -> tuple[float, float]:
    return (math.cos(theta) * c.vx - math.sin(theta) * c.vy, math.sin(theta) * c.vx + math.cos(theta) * c.vy)


def test_advance_defender_blocks_the_kick_line_one_metre_from_the_carrier():
    robot = _robot("AD", n=2)
    carrier, ball = (-1.0, 0.0), (-1.35, 0.0)  # opponent dribbling towards our goal at -x
    sense = Sense(
        tick=10,
        pose=Pose(x=-3.0, y=0.8, theta=0.0),
        ball=BallSeen(visible=True, x=ball[0], y=ball[1]),
        robots=[RobotSeen(team="b", x=carrier[0], y=carrier[1])],
    )
    own = [TeamPose(robot=1, x=2.0, y=0.0, role="attacker"), TeamPose(robot=2, x=-3.0, y=0.8, role="defender")]
    cmd = None
    for t in range(10, 14):
        cmd = robot.step(t, sense, _order(9, 2, "defender", R.DEFENDING_DEFENDER, own=own))
    vx, vy = _body_to_field(cmd, 0.0)
    block = S.block_point(carrier, (-6.0, 0.0), S.SkillParams())
    assert block == pytest.approx((-2.0, 0.0))
    assert vx > 0.0 and vy < 0.0  # towards the block point on the line carrier -> goal
    assert cmd.dribbler  # ready to take the ball when the carrier comes within 0.5 m


def _holding(name: str, pos: tuple[float, float], opponents: list[tuple[float, float]], tick: int = 20) -> Cmd:
    """A robot holding the ball at pos, facing the +x goal, left to turn (its heading follows its
    own omega) for up to 1 s: its first kick command, else its last command."""
    robot = _robot(name)
    theta = S.angle_to(pos, (6.0, 0.0))
    own = [TeamPose(robot=1, x=pos[0], y=pos[1], role="attacker"), TeamPose(robot=2, x=-3.0, y=0.0, role="defender")]
    order = _order(tick - 1, 1, "attacker", R.ATTACKING_ATTACKER, own=own)
    cmd = Cmd(tick=0)
    for t in range(tick, tick + 50):
        ball = (pos[0] + REACH * math.cos(theta), pos[1] + REACH * math.sin(theta))
        sense = Sense(
            tick=t,
            pose=Pose(x=pos[0], y=pos[1], theta=theta),
            omega=cmd.omega,
            ball=BallSeen(visible=True, x=ball[0], y=ball[1]),
            robots=[RobotSeen(team="b", x=x, y=y) for x, y in opponents],
            has_ball=True,
        )
        cmd = robot.step(t, sense, order)
        if cmd.kick_speed > 0.0:
            return cmd
        theta += cmd.omega * CFG.timing.dt
    return cmd


def test_basic_attacker_kicks_from_the_set_distance_even_into_a_defender():
    cmd = _holding("BS", (1.5, 0.4), [(2.6, 0.4), (5.65, 0.0)])  # 4.5 m out, a defender 1.1 m ahead
    assert cmd.kick_speed == pytest.approx(8.0)


def test_advance_attacker_does_not_shoot_into_a_blocker_and_shoots_when_clear():
    blocked = _holding("AD", (1.5, 0.4), [(2.6, 0.4), (5.65, 0.0)])
    assert blocked.kick_speed == 0.0
    clear = _holding("AD", (2.0, 0.4), [(2.2, 3.0), (5.65, -0.3)])  # 4 m out, only the keeper in front
    assert clear.kick_speed == pytest.approx(8.0)


def test_a_robot_that_loses_the_ball_steps_off_it_with_the_dribbler_off():
    robot = _robot("BS")
    pose = Pose(x=0.0, y=0.0, theta=0.0)
    ball = BallSeen(visible=True, x=REACH, y=0.0)
    tackler = [RobotSeen(team="b", x=REACH + 0.45, y=0.0)]
    own = [TeamPose(robot=1, x=0.0, y=0.0, role="attacker")]
    robot.step(
        30,
        Sense(tick=30, pose=pose, ball=ball, robots=tackler, has_ball=True),
        _order(29, 1, "attacker", R.ATTACKING_ATTACKER, own=own),
    )
    cmd = robot.step(
        31,
        Sense(tick=31, pose=pose, ball=ball, robots=tackler, has_ball=False),
        _order(29, 1, "attacker", R.ATTACKING_ATTACKER, own=own),
    )
    assert not cmd.dribbler and cmd.vx < 0.0  # backs straight off the ball instead of wrestling for it


def test_the_push_guard_stops_a_robot_from_shoving_an_opponent():
    robot = _robot("AD")
    sense = Sense(
        tick=5,
        pose=Pose(x=0.0, y=0.0, theta=0.0),
        robots=[RobotSeen(team="b", x=0.55, y=0.0)],
        ball=BallSeen(visible=True, x=-3.0, y=0.0),
    )
    robot.step(5, sense, _order(4, 1, "attacker", R.ATTACKING_ATTACKER))
    cmd = robot.drive(5, (3.0, 0.0), 0.0, 2.5, avoid=False)  # straight through the opponent in contact
    assert cmd.vx <= 1e-9
    far = robot.guard_push(0.0, 0.0, 2.5, 0.0, 0.65)  # 0.55 m away: in contact
    assert far[0] == pytest.approx(0.0)
    sense = Sense(tick=6, pose=Pose(x=0.0, y=0.0, theta=0.0), robots=[RobotSeen(team="b", x=1.5, y=0.0)])
    robot.step(6, sense, _order(4, 1, "attacker", R.ATTACKING_ATTACKER))
    vx, _ = robot.guard_push(0.0, 0.0, 2.5, 0.0, 0.65)
    assert vx == pytest.approx(math.sqrt(0.5**2 + 2 * 1.2 * (1.5 - 0.65)))  # what it can still brake from


def test_the_push_guard_acts_on_where_the_robots_are_now_not_where_they_were_seen():
    """The view is `perception_latency` ticks late; an opponent coming at 1 m/s is 0.06 m nearer than seen
    (60 ms), and a robot moving at 1 m/s is 0.06 m farther on: the guard caps on the present gap."""
    robot = _robot("AD")
    lat = CFG.timing.perception_latency
    lead = lat * CFG.timing.dt
    assert lat == 3  # the model's default: 60 ms
    for k in range(10):
        sense = Sense(
            tick=k,
            pose=Pose(x=0.0, y=0.0, theta=0.0),
            vx=1.0,
            robots=[RobotSeen(team="b", x=2.0 - 0.02 * k + (0.01 if k % 2 else -0.01), y=0.0)],
            ball=BallSeen(visible=True, x=-3.0, y=0.0),
        )
        robot.step(k + lat, sense, _order(k + lat - 1, 1, "attacker", R.ATTACKING_ATTACKER))
    seen = robot.view.opponents[0][0]
    ((now_x, _),) = robot.view.opponents_now
    assert seen == pytest.approx(1.83)  # the last detection: 2.0 - 0.18 + 0.01 of noise
    assert now_x == pytest.approx(1.82 - 1.0 * lead, abs=0.02)  # the regressed 1 m/s, 60 ms on
    assert robot.view.pose_now == pytest.approx((lead, 0.0))
    vx, _ = robot.guard_push(*robot.view.pose_now, 2.5, 0.0, 0.65)
    gap = now_x - lead
    assert vx == pytest.approx(math.sqrt(0.5**2 + 2 * 1.2 * (gap - 0.65)), abs=0.02)


# ----------------------------------------------------------------- physics
def test_the_loser_of_a_challenge_cannot_win_the_ball_straight_back():
    """Face to face at one ball, both dribblers on: without NO_CHALLENGE_S the ball changes holder every tick."""
    ph = Physics(CFG.replace(robots=1))
    ph.place_robot("a", 0, 0.0, 0.0, 0.0)
    ph.place_robot("b", 0, 2 * REACH + 0.02, 0.0, math.pi)  # its front face at the ball too
    ph.place_ball(REACH + 0.01, 0.0)
    ph.set_command("a", 0, Cmd(tick=0, dribbler=True))
    ph.step()
    assert ph.holder() == ("a", 0)
    ph.set_command("b", 0, Cmd(tick=0, dribbler=True))  # b challenges and takes the ball
    holders = []
    for _ in range(12):
        ph.step()
        holders.append(ph.holder())
    first = holders.index(("b", 0))
    quiet = math.ceil(NO_CHALLENGE_S / CFG.timing.dt)
    assert first <= 2
    # a, the loser, still touches the ball with its dribbler on, but b keeps it until a may challenge again
    assert all(h == ("b", 0) for h in holders[first : quiet - 1]), holders


# ------------------------------------------------- advance defense (issue 4, goal rates)
def test_block_point_is_on_the_ball_kick_line_one_metre_from_the_carrier():
    p = S.SkillParams()
    carrier, ball, own = (0.0, 0.0), (-0.33, -0.1), (-6.0, 0.0)  # the carrier holds the ball turned off its own line
    block = S.block_point(carrier, own, p, ball)
    seg, _ = S.segment_distance(block, ball, own)
    assert seg == pytest.approx(0.0, abs=1e-9)  # on the ball's line to our goal centre, where the kick starts
    assert S.dist(block, ball) == pytest.approx(p.block_distance - S.dist(carrier, ball))
    # the old carrier-centre line leaves this kick line uncovered by more than the shooter's clear margin
    assert S.segment_distance(S.block_point(carrier, own, p), ball, (-6.0, -0.9))[0] > 0.0
    # a carrier holding the ball at arm's length still leaves block_gap between ball and blocker
    assert S.dist(S.block_point(carrier, own, p, (-0.6, 0.0)), (-0.6, 0.0)) == pytest.approx(p.block_gap)
    # retreat: never nearer our goal centre than retreat_radius
    assert S.dist(S.block_point((-3.2, 0.0), own, p, (-3.5, 0.0)), own) == pytest.approx(p.retreat_radius)


def _defending_view(robot, pose, ball, opponents, own, tick=10):
    cmd = None
    for t in range(tick, tick + 4):
        sense = Sense(
            tick=t,
            pose=Pose(x=pose[0], y=pose[1], theta=0.0),
            ball=BallSeen(visible=True, x=ball[0], y=ball[1]),
            robots=[RobotSeen(team="b", x=x, y=y) for x, y in opponents],
        )
        cmd = robot.step(
            t,
            sense,
            _order(
                tick - 1,
                robot.n,
                robot.role or "defender",
                R.DEFENDING_DEFENDER if robot.n == 2 else R.DEFENDING_ATTACKER,
                own=own,
            ),
        )
    return cmd


def test_advance_attacker_drops_back_to_mark_when_the_ball_is_deep_in_our_half():
    carrier, ball, other = (-2.0, 1.0), (-2.33, 1.0), (-3.0, -2.0)
    own = [TeamPose(robot=1, x=0.0, y=-1.0, role="attacker"), TeamPose(robot=2, x=-3.5, y=0.8, role="defender")]
    for name, marks in (("AD", True), ("BD", False)):
        robot = _robot(name, n=1)
        robot.role = "attacker"
        cmd = _defending_view(robot, (0.0, -1.0), ball, [carrier, other], own)
        vx, vy = _body_to_field(cmd, 0.0)
        mark = S.mark_point(other, (-6.0, 0.0), S.SkillParams().mark_distance)
        towards = (vx * (mark[0] - 0.0) + vy * (mark[1] + 1.0)) / S.dist(mark, (0.0, -1.0))
        if marks:  # advance: the second outfield robot marks the other attacker goal-side
            assert towards > 0.9 * math.hypot(vx, vy) > 0.0
        else:  # basic: it waits ahead of the ball for the counter-attack
            assert vx >= 0.0


def test_the_robot_nearest_the_kick_line_blocks_and_the_other_marks():
    carrier, ball, other = (-1.0, 0.0), (-1.33, 0.0), (-2.5, 2.0)
    own = [TeamPose(robot=1, x=-2.2, y=0.3, role="attacker"), TeamPose(robot=2, x=0.5, y=-0.5, role="defender")]
    block = S.block_point(carrier, (-6.0, 0.0), S.SkillParams(), ball)
    near = _robot("AD", n=1)
    near.role = "attacker"
    vx, vy = _body_to_field(_defending_view(near, (-2.2, 0.3), ball, [carrier, other], own), 0.0)
    assert vx * (block[0] + 2.2) + vy * (block[1] - 0.3) > 0.0  # goal-side and nearer: it blocks
    far = _robot("AD", n=2)  # the defender behind the carrier: it would have to go round it, so it marks
    vx, vy = _body_to_field(_defending_view(far, (0.5, -0.5), ball, [carrier, other], own), 0.0)
    mark = S.mark_point(other, (-6.0, 0.0), S.SkillParams().mark_distance)
    assert vx * (mark[0] - 0.5) + vy * (mark[1] + 0.5) > 0.9 * math.hypot(vx, vy) * S.dist(mark, (0.5, -0.5))


def test_static_roles_keep_each_robot_in_its_fig5_area():
    """Paper 2, Fig. 5: the attacker's area starts 0.5 m behind the centre line; with static roles the
    attacker nearest the kick line neither blocks nor marks in our half, the defender blocks."""
    carrier, ball, other = (-1.0, 0.0), (-1.33, 0.0), (-2.5, 2.0)
    own = [TeamPose(robot=1, x=-2.2, y=0.3, role="attacker"), TeamPose(robot=2, x=0.5, y=-0.5, role="defender")]
    block = S.block_point(carrier, (-6.0, 0.0), S.SkillParams(), ball)
    for name, pose in (("AS", (-2.2, 0.3)), ("BS", (-2.2, 0.3)), ("AS", (-0.4, 2.5))):
        near = _robot(name, n=1)
        near.role = "attacker"
        vx, _ = _body_to_field(_defending_view(near, pose, ball, [carrier, other], own), 0.0)
        assert vx > 0.0 or pose[0] > -0.5 and vx >= 0.0, (name, pose)  # back into its area, or staying there
    far = _robot("AS", n=2)  # the defender blocks, though it has to go round the carrier
    vx, vy = _body_to_field(_defending_view(far, (0.5, -0.5), ball, [carrier, other], own), 0.0)
    assert vx < 0.0 and far.mem.blocking
    dynamic = _robot("AD", n=1)  # dynamic roles are not confined: the nearest robot blocks (test above)
    dynamic.role = "attacker"
    vx, vy = _body_to_field(_defending_view(dynamic, (-2.2, 0.3), ball, [carrier, other], own), 0.0)
    assert vx * (block[0] + 2.2) + vy * (block[1] - 0.3) > 0.0


def test_advance_defense_walls_the_kick_line_at_an_opponent_free_kick():
    spot = (-1.0, 1.0)
    own = [TeamPose(robot=1, x=-3.0, y=0.0, role="attacker"), TeamPose(robot=2, x=1.0, y=0.0, role="defender")]
    robot = _robot("AD", n=1)
    sense = Sense(tick=5, pose=Pose(x=-3.0, y=0.0, theta=0.0), ball=BallSeen(visible=True, x=spot[0], y=spot[1]))
    fk = Order(
        tick=4,
        robot=1,
        command="FREEKICK",
        command_team="b",
        spot_x=spot[0],
        spot_y=spot[1],
        attack_dir=1,
        role="attacker",
        own=own,
    )
    wall = robot.setpiece_defense(fk, spot) if robot.step(5, sense, fk) is not None else None
    assert S.segment_distance(wall, spot, (-6.0, 0.0))[0] == pytest.approx(0.0, abs=1e-9)  # on the kick line
    assert S.dist(wall, spot) == pytest.approx(2.2)  # as near as the rules allow, and a little more
    # nearer our goal the wall does not back into the keeper: at least retreat_radius - 1 m from the goal centre
    assert S.dist(robot.setpiece_defense(fk, (-4.0, 0.5)), (-6.0, 0.0)) == pytest.approx(2.0)
