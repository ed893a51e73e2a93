"""Strategies: the conformance suite over every registered strategy and a plugin,
the plugin entry point, the role FSM (paper 2 Fig. 6), S1/S2/S3, eq. 6, fusion
(eq. 5) and the skills' geometry."""

from __future__ import annotations

import math
import random
from importlib import metadata

import pytest

from arena.config import MatchConfig, SensorParams
from arena.schemas.messages import BallSeen, Cmd, Order, Pose, RefCommand, Referee, Report, RobotSeen, Sense, TeamPose
from arena.strategies import conformance, registry
from arena.strategies import roles as R
from arena.strategies import skills as S
from arena.strategies.base import RobotContext, Strategy, TeamContext
from arena.strategies.world import RobotView, TeamModel


# ------------------------------------------------------------ a plugin strategy
class _StandTeam:
    def __init__(self, ctx: TeamContext):
        self.robots = ctx.cfg.robots

    def step(self, tick, reports, referee):
        command = referee.command if referee is not None else "STOP"
        return {n: Order(tick=tick, robot=n, command=command) for n in range(self.robots)}


class _CreepRobot:
    """Creeps forward at 0.3 m/s while the referee says START."""

    def __init__(self, ctx: RobotContext):
        self.n = ctx.n

    def step(self, tick, sense, order):
        if sense is None or order is None or order.command != "START":
            return Cmd(tick=tick)
        return Cmd(tick=tick, vx=0.3)

    def report(self, tick, sense):
        pose = sense.pose if sense is not None else Pose(x=0.0, y=0.0, theta=0.0)
        return Report(tick=tick, robot=self.n, pose=pose)


PLUGIN = Strategy(
    name="creep", make_team=_StandTeam, make_robot=_CreepRobot, aliases=("CR",), description="test plugin"
)


@pytest.mark.parametrize("name", sorted(registry.all_strategies()))
@pytest.mark.parametrize("check", conformance.CHECKS, ids=lambda c: c.__name__)
def test_conformance_of_every_registered_strategy(name, check):
    check(registry.get(name), MatchConfig())


@pytest.mark.parametrize("check", conformance.CHECKS, ids=lambda c: c.__name__)
def test_conformance_of_a_plugin_strategy(check):
    check(PLUGIN, MatchConfig(robots=2))


def test_conformance_catches_a_broken_strategy():
    class Fast(_CreepRobot):
        def step(self, tick, sense, order):
            return Cmd(tick=tick, vx=50.0)

    broken = Strategy(name="broken", make_team=_StandTeam, make_robot=Fast)
    with pytest.raises(AssertionError, match="speed"):
        conformance.check_commands(broken, MatchConfig())
    with pytest.raises(AssertionError, match="moves under STOP"):
        conformance.check_stop(broken, MatchConfig())


def test_a_plugin_entry_point_is_found_and_plays(monkeypatch):
    class EP:
        name = "creep"
        group = registry.GROUP

        def load(self):
            return lambda: PLUGIN

    real = metadata.entry_points

    def fake(**kw):
        return [EP()] if kw.get("group") == registry.GROUP else real(**kw)

    monkeypatch.setattr(metadata, "entry_points", fake)  # registry imports it when it needs it
    registry.all_strategies.cache_clear()
    try:
        assert registry.resolve_name("cr") == "creep"
        assert registry.get("creep") is PLUGIN
        assert registry.resolve_name("AD") == "advance-dynamic"  # built-ins still there
        from arena.match.inprocess import play_in_process

        summaries, _ = play_in_process(MatchConfig(seed=2, home="creep", away="BS", half_time=1.0), watch=())
        assert [e["command"] for e in summaries["referee"].extra["log"][-3:]] == ["END_GAME", "PARK", "GAMEOVER"]
    finally:
        registry.all_strategies.cache_clear()


def test_paper_names_and_chase_are_registered():
    names = registry.all_strategies()
    for name, alias in (
        ("basic-static", "BS"),
        ("basic-dynamic", "BD"),
        ("advance-static", "AS"),
        ("advance-dynamic", "AD"),
    ):
        assert registry.resolve_name(alias) == name
        assert names[name].make_robot.__module__.endswith("iris")
    assert "chase" in names


# ---------------------------------------------------------------- roles, eq. 6
@pytest.mark.parametrize(
    ("state", "inp", "want"),
    [
        (R.DEFENDING_DEFENDER, R.B, R.ATTACKING_DEFENDER),
        (R.DEFENDING_ATTACKER, R.B, R.ATTACKING_ATTACKER),
        (R.ATTACKING_DEFENDER, R.B_BAR, R.DEFENDING_DEFENDER),
        (R.ATTACKING_ATTACKER, R.B_BAR, R.DEFENDING_ATTACKER),
        (R.ATTACKING_DEFENDER, R.A, R.ATTACKING_ATTACKER),
        (R.DEFENDING_DEFENDER, R.A, R.DEFENDING_ATTACKER),
        (R.ATTACKING_ATTACKER, R.D, R.ATTACKING_DEFENDER),
        (R.DEFENDING_ATTACKER, R.D, R.DEFENDING_DEFENDER),
        # no arrow: the state stays
        (R.ATTACKING_ATTACKER, R.B, R.ATTACKING_ATTACKER),
        (R.DEFENDING_DEFENDER, R.B_BAR, R.DEFENDING_DEFENDER),
        (R.ATTACKING_ATTACKER, R.A, R.ATTACKING_ATTACKER),
        (R.DEFENDING_DEFENDER, R.D, R.DEFENDING_DEFENDER),
    ],
)
def test_fig6_transition(state, inp, want):
    assert R.transition(state, inp) == want


@pytest.mark.parametrize(
    ("own", "opp", "want"), [(0, 0, R.S_LEVEL), (2, 2, R.S_LEVEL), (0, 1, R.S_OFFENSIVE), (3, 1, R.S_DEFENSIVE)]
)
def test_strategy_choice(own, opp, want):
    assert R.choose_strategy(own, opp) == want


@pytest.mark.parametrize(("n", "n_d"), [(1, 1), (2, 1), (3, 2), (4, 2), (5, 3)])
def test_eq6_defender_count(n, n_d):
    assert R.n_defenders(n) == n_d
    assigner = R.RoleAssigner(n + 1, dynamic=False, p=R.AreaParams())
    assert list(assigner.roles().values()).count("defender") == n_d


def test_areas_overlap_by_one_metre_and_split_into_bands():
    p = R.AreaParams(field_length=12.0, overlap=1.0)
    assert p.defense == (-6.0, 0.5) and p.attack == (-0.5, 6.0)
    two = R.areas({1: "defender", 2: "defender", 3: "attacker"}, p)
    assert two[1] == pytest.approx((-6.0, -2.75)) and two[2] == pytest.approx((-2.75, 0.5))
    assert two[3] == (-0.5, 6.0)


def _assigner(dynamic):
    a = R.RoleAssigner(3, dynamic=dynamic, p=R.AreaParams())
    assert a.roles() == {1: "attacker", 2: "defender"}
    return a


def test_possession_moves_every_robot_between_attacking_and_defending():
    a = _assigner(dynamic=True)
    a.update("own", 1, {1: 2.0, 2: -3.0}, {1: (2.0, 0.0), 2: (-3.0, 0.0)})
    assert a.state == {1: R.ATTACKING_ATTACKER, 2: R.ATTACKING_DEFENDER}
    a.update("", None, {}, {})
    assert a.state == {1: R.ATTACKING_ATTACKER, 2: R.ATTACKING_DEFENDER}  # loose ball: no input
    a.update("opponent", None, {}, {})
    assert a.state == {1: R.DEFENDING_ATTACKER, 2: R.DEFENDING_DEFENDER}


def test_dynamic_defender_with_the_ball_in_the_attack_area_swaps_with_the_nearest_attacker():
    a = _assigner(dynamic=True)
    a.update("own", 2, {1: 3.0, 2: 0.0}, {1: (3.0, 0.0), 2: (0.0, 0.0)})  # captured at u = 0 (overlap)
    assert a.roles() == {1: "defender", 2: "attacker"} and a.swaps == 1
    a.update("own", 2, {1: 3.0, 2: 0.2}, {1: (3.0, 0.0), 2: (0.2, 0.0)})  # still holding inside the overlap
    assert a.roles() == {1: "defender", 2: "attacker"} and a.swaps == 1


def test_dynamic_attacker_with_the_ball_in_the_defensive_area_swaps():
    a = _assigner(dynamic=True)
    a.update("own", 1, {1: -2.0, 2: -4.0}, {1: (-2.0, 0.0), 2: (-4.0, 0.0)})
    assert a.roles() == {1: "defender", 2: "attacker"}
    assert a.state == {1: R.ATTACKING_DEFENDER, 2: R.ATTACKING_ATTACKER}


def test_dynamic_defender_carrying_past_its_area_swaps():
    a = _assigner(dynamic=True)
    a.update("own", 2, {1: 3.0, 2: -2.0}, {1: (3.0, 0.0), 2: (-2.0, 0.0)})  # captured deep: no swap
    assert a.roles() == {1: "attacker", 2: "defender"}
    a.update("own", 2, {1: 3.0, 2: 0.7}, {1: (3.0, 0.0), 2: (0.7, 0.0)})  # out of the defensive area
    assert a.roles() == {1: "defender", 2: "attacker"}


def test_static_roles_never_swap():
    a = _assigner(dynamic=False)
    a.update("own", 2, {1: 3.0, 2: 0.7}, {1: (3.0, 0.0), 2: (0.7, 0.0)})
    a.update("own", 1, {1: -3.0, 2: 0.7}, {1: (-3.0, 0.0), 2: (0.7, 0.0)})
    assert a.roles() == {1: "attacker", 2: "defender"} and a.swaps == 0


@pytest.mark.parametrize("dynamic", [False, True])
def test_a_robot_sent_off_leaves_the_roles_and_eq6_holds_for_the_robots_left(dynamic):
    a = _assigner(dynamic)
    a.update("opponent", None, {}, {})
    a.send_off(2)  # the defender: the attacker left alone defends (n_d = ceil(1/2) = 1)
    assert a.roles() == {1: "defender"} and a.state == {1: R.DEFENDING_DEFENDER}
    a.send_off(2)  # again (the same referee frame twice): nothing more
    assert a.roles() == {1: "defender"}
    four = R.RoleAssigner(5, dynamic=dynamic, p=R.AreaParams())  # 4 outfield: 1, 2 attack; 3, 4 defend
    four.send_off(1)
    assert four.roles() == {2: "attacker", 3: "defender", 4: "defender"}  # 3 left: n_d = 2
    four.send_off(2)
    assert four.roles() == {3: "attacker", 4: "defender"}  # 2 left: one of each


def test_the_base_station_reassigns_roles_after_a_send_off():
    cfg = MatchConfig()
    team = registry.get("AS").make_team(TeamContext(cfg=cfg, team="a", rng=random.Random(0)))
    reports = {n: _report(n, -1.0 * n, 0.0) for n in range(3)}
    before = team.step(10, reports, Referee(tick=10, stage="FIRST_HALF", command="START"))
    assert before[1].role == "attacker" and before[2].role == "defender"
    card = RefCommand(name="DOUBLE_YELLOW", team="a", robot=2, tick=15)
    after = team.step(15, reports, Referee(tick=15, stage="FIRST_HALF", command="STOP", commands=[card]))
    assert after[1].role == "defender"
    other = RefCommand(name="DOUBLE_YELLOW", team="b", robot=1, tick=20)
    again = team.step(20, reports, Referee(tick=20, stage="FIRST_HALF", command="STOP", commands=[other]))
    assert again[1].role == "defender"  # the other team's card changes nothing here


# ------------------------------------------------------------- fusion, eq. 5
def _report(n, x, y, ball=None, robots=(), tick=10, has_ball=False):
    b = BallSeen(visible=True, x=ball[0], y=ball[1]) if ball else BallSeen()
    return Report(tick=tick, robot=n, pose=Pose(x=x, y=y, theta=0.0), ball=b, robots=list(robots), has_ball=has_ball)


def test_ball_fusion_weights_near_detections_more():
    m = TeamModel("a", 3, SensorParams(), 0.02)
    m.update(10, {1: _report(1, 0.0, 0.0, ball=(1.0, 0.0)), 2: _report(2, 5.0, 0.0, ball=(1.4, 0.0))})
    x, y = m.ball_xy(10)
    # sigma(1 m) = 0.04, sigma(3.6 m) = 0.066: weights 625 and 230
    assert x == pytest.approx((625 * 1.0 + 1 / 0.066**2 * 1.4) / (625 + 1 / 0.066**2), rel=1e-3)
    assert y == 0.0


def test_opponent_fusion_merges_close_detections_and_remembers_unseen_ones():
    m = TeamModel("a", 3, SensorParams(), 0.02)
    seen1 = [RobotSeen(team="b", x=2.0, y=1.0), RobotSeen(team="b", x=-1.0, y=-2.0), RobotSeen(team="a", x=0.0, y=0.0)]
    seen2 = [RobotSeen(team="b", x=2.1, y=1.0)]
    m.update(10, {1: _report(1, 1.0, 0.0, robots=seen1), 2: _report(2, 3.0, 0.0, robots=seen2)})
    assert len(m.opponents) == 2  # own-team detections are not opponents
    near = min(m.opponents, key=lambda t: abs(t.x - 2.0))
    assert 2.0 < near.x < 2.1
    m.update(20, {1: _report(1, 1.0, 0.0, robots=seen2, tick=20)})
    assert sorted((round(t.x, 1), t.tick) for t in m.opponents) == [(-1.0, 10), (2.1, 20)]
    m.update(200, {1: _report(1, 1.0, 0.0, tick=200)})
    assert m.opponents == []


def test_holder_and_poses_come_from_reports():
    m = TeamModel("a", 3, SensorParams(), 0.02)
    m.update(10, {2: _report(2, 1.0, 2.0, has_ball=True)})
    assert m.holder() == 2 and m.own[2][:2] == (1.0, 2.0)


def test_robot_view_uses_its_own_ball_else_the_base_station_model():
    v = RobotView("a", 1, SensorParams(), 0.02)
    order = Order(
        tick=10,
        robot=1,
        ball_valid=True,
        ball_x=3.0,
        ball_y=-1.0,
        ball_age=2,
        opponents=[TeamPose(robot=-1, x=4.0, y=0.0)],
        own=[TeamPose(robot=2, x=-2.0, y=0.0, role="defender")],
    )
    sense = Sense(tick=12, pose=Pose(x=0.0, y=0.0, theta=0.0), ball=BallSeen(visible=True, x=1.0, y=0.5))
    v.update(12, sense, order)
    assert v.ball == (1.0, 0.5) and v.ball_age == 0
    assert v.opponents == [(4.0, 0.0)] and v.mates == {2: (-2.0, 0.0, "defender")}
    blind = Sense(tick=13, pose=Pose(x=0.0, y=0.0, theta=0.0), robots=[RobotSeen(team="b", x=4.1, y=0.0)])
    v.update(13, blind, order)
    assert v.ball == (1.0, 0.5) and v.ball_age == 1  # own sighting 1 tick old beats the order's 5
    fresh = Order(
        tick=38,
        robot=1,
        ball_valid=True,
        ball_x=3.0,
        ball_y=-1.0,
        ball_age=0,
        opponents=[TeamPose(robot=-1, x=4.0, y=0.0)],
    )
    v.update(40, blind, fresh)
    assert v.ball == (3.0, -1.0) and v.ball_age == 2  # own sighting (27 ticks) older than the base station's
    assert v.opponents == [(4.1, 0.0)]  # the order's P_B entry is explained by an own detection


def test_robot_view_tracks_opponents_and_predicts_them_by_the_latency():
    v = RobotView("a", 1, SensorParams(), 0.02, latency=3)
    for k in range(12):  # b at 2 m/s along +y; a second opponent appears at tick 10
        robots = [RobotSeen(team="b", x=1.0, y=0.04 * k)] + ([RobotSeen(team="b", x=-2.0, y=0.0)] if k >= 10 else [])
        v.update(k + 3, Sense(tick=k, pose=Pose(x=0.0, y=0.0, theta=0.0), robots=robots), None)
    assert v.opponents == [(1.0, 0.44), (-2.0, 0.0)]  # what it saw, 60 ms ago
    (x, y), second = v.opponents_now
    assert (x, y) == pytest.approx((1.0, 0.44 + 2.0 * 0.06)) and second == (-2.0, 0.0)  # the new one: no velocity yet
    assert RobotView("a", 1, SensorParams(), 0.02).opponents_now is not None  # no latency: the view itself


# ------------------------------------------------------------------ skills
def test_behind_point_and_lined_up():
    assert S.behind_point((1.0, 0.0), (6.0, 0.0), 0.4) == pytest.approx((0.6, 0.0))
    assert S.lined_up((0.5, 0.05), (1.0, 0.0), (6.0, 0.0), 0.1)
    assert not S.lined_up((1.5, 0.0), (1.0, 0.0), (6.0, 0.0), 0.1)  # in front of the ball


def test_line_clear_and_best_aim():
    assert S.line_clear((0.0, 0.0), (6.0, 0.0), [(3.0, 1.0)], 0.36)
    assert not S.line_clear((0.0, 0.0), (6.0, 0.0), [(3.0, 0.2)], 0.36)
    aim, clear = S.best_aim((3.0, 0.0), 6.0, 1.0, [(5.6, 0.5)], 0.36)
    assert aim[0] == 6.0 and aim[1] < 0 and clear  # keeper on the left: aim right


def test_blocker_and_sidestep_away_from_the_near_touch_line():
    pos, goal = (0.0, 2.0), (6.0, 0.0)
    opp = (1.0, 1.85)
    assert S.blocker_ahead(pos, goal, [opp, (-1.0, 2.0)], 0.6, 1.6) == opp
    assert S.blocker_ahead(pos, goal, [(3.0, 2.0)], 0.6, 1.6) is None  # too far ahead
    side, _, _ = S.circle_past(pos, opp, goal, 1.0)
    assert side[1] < opp[1]  # robot on the left (y > 0) goes right, towards the middle
    assert S.passed((2.0, 1.0), opp, goal) and not S.passed(pos, opp, goal)


@pytest.mark.parametrize(
    ("carrier", "want"),
    [
        ((0.0, 0.0), (-1.0, 0.0)),  # 1 m in front of the carrier on its line to our goal (-6, 0)
        ((-3.5, 0.0), (-3.0, 0.0)),  # retreat stops at 3 m from the goal centre
        ((-4.0, 2.0), (-6.0 + 3.0 * 2 / math.hypot(2, 2), 3.0 * 2 / math.hypot(2, 2))),  # follows the ball's bearing
    ],
)
def test_advance_defense_block_point(carrier, want):
    assert S.block_point(carrier, (-6.0, 0.0), S.SkillParams()) == pytest.approx(want)


def test_keeper_guards_the_mouth_and_intercepts_the_predicted_path():
    p = S.SkillParams()
    (x, y), intercept = S.keeper_target((0.0, 3.0), (0.0, 0.0), -6.0, 1.0, p)
    assert not intercept and x == pytest.approx(-5.65) and 0 < y <= 0.8
    (x, y), intercept = S.keeper_target((-3.0, 0.0), (-3.0, -0.5), -6.0, 1.0, p)
    assert intercept and y == pytest.approx(-0.5 * 2.65 / 3.0)
    assert S.predict_crossing((-3.0, 0.0), (3.0, 0.0), -5.65) is None  # moving away


def test_pass_speed_arrives_at_the_wanted_speed():
    v = S.pass_speed(4.0, 1.5, 0.4, 8.0)
    assert v * v - 2 * 0.4 * 4.0 == pytest.approx(1.5**2)


def test_iris_robot_obeys_stop_and_positions_for_an_opponent_set_piece():
    strategy = registry.get("AD")
    cfg = MatchConfig()
    robot = strategy.make_robot(RobotContext(cfg=cfg, team="a", n=1, rng=random.Random(0)))
    sense = Sense(tick=5, pose=Pose(x=0.5, y=0.0, theta=0.0), ball=BallSeen(visible=True, x=0.0, y=0.0))
    assert robot.step(5, sense, Order(tick=4, robot=1, command="STOP", role="attacker")) == Cmd(tick=5)
    fk = Order(tick=4, robot=1, command="FREEKICK", command_team="b", spot_x=0.0, spot_y=0.0, role="attacker")
    c = robot.step(6, sense, fk)
    assert c.vx * 0.5 > 0 and math.hypot(c.vx, c.vy) > 0.5  # heading away from the spot at the origin (facing +x)


def _example_plugin() -> Strategy:
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "arena_wall" / "arena_wall" / "__init__.py"
    spec = importlib.util.spec_from_file_location("arena_wall", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.STRATEGY


def test_the_example_plugin_package_passes_the_conformance_suite():
    conformance.check_all(_example_plugin())


def test_arena_strategies_runs_the_suite_again_only_for_changed_source(tmp_path, monkeypatch):
    """`arena strategies` ran the conformance suite for every strategy on every call (42 s on a
    loaded host): a verdict is now kept by source hash in the user's cache dir."""
    import sys

    from arena.strategies import checked, registry

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    runs = []
    monkeypatch.setattr(conformance, "check_all", lambda s: runs.append(s.name))
    rows = registry.describe(only={"chase"})
    assert (runs, rows[0]["conformance"], rows[0]["cached"]) == (["chase"], "passes", False)
    rows = registry.describe(only={"chase"})
    assert (runs, rows[0]["conformance"], rows[0]["cached"]) == (["chase"], "passes", True)
    registry.describe(only={"chase"}, recheck=True)
    assert runs == ["chase", "chase"]
    assert (tmp_path / "cache" / "soccer-arena" / checked.CACHE_FILE).exists()

    # A plugin's own source is part of the key: an edit to its package runs the suite again.
    pkg = tmp_path / "src" / "edited_plugin"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("from arena.strategies.simple import *  # noqa\n")
    monkeypatch.syspath_prepend(str(tmp_path / "src"))
    import edited_plugin

    s = Strategy(
        name="edited", make_team=type("T", (_StandTeam,), {"__module__": "edited_plugin"}), make_robot=_CreepRobot
    )
    assert checked.verdict(s) == ("passes", False) and checked.verdict(s) == ("passes", True)
    (pkg / "__init__.py").write_text("# edited\n")
    assert checked.verdict(s) == ("passes", False)
    del sys.modules[edited_plugin.__name__]
