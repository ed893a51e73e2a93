"""Control as messages: teleports and referee overrides applied at a tick, inside the digest.

sim/director.py (the engine's share), rules/referee_box.py `Forced` (the
referee's); played in process, where the digests are those of real processes.
"""

from __future__ import annotations

import math

import msgspec
import pytest

from arena.config import ConfigError, MatchConfig, ScenarioParams
from arena.match.inprocess import play_in_process
from arena.rules.referee_box import Forced, RefereeState, Rules, process
from arena.schemas.messages import (
    Condition,
    Operator,
    RefereeOverride,
    Region,
    Step,
    TeleportBall,
    TeleportRobot,
    World,
)
from arena.sim.director import referee_steps


def play(steps, ticks=60, stage="FIRST_HALF", seed=3, **kw):
    cfg = MatchConfig(
        seed=seed, home="BS", away="BS", scenario=ScenarioParams(ticks=ticks, stage=stage, steps=steps, **kw)
    )
    summaries, frames = play_in_process(cfg, watch=("world", "referee"))
    dec = msgspec.msgpack.Decoder(World).decode
    worlds = [dec(p) for p in frames["world"]]
    refs = [msgspec.msgpack.decode(p) for p in frames["referee"]]
    return summaries, worlds, refs


def robot(w: World, team: str, n: int):
    return next(r for r in w.robots if r.team == team and r.robot == n)


def test_teleports_apply_at_their_tick():
    steps = (
        Step(at=0, actions=[RefereeOverride(command="START")]),
        Step(
            at=10,
            actions=[
                TeleportBall(x=1.0, y=2.0, vx=0.0, vy=0.0),
                TeleportRobot(team="b", robot=1, x=-2.0, y=-3.0, orientation=1.0),
            ],
        ),
        Step(at=20, actions=[TeleportRobot(team="a", robot=2, present=False)]),
    )
    _, worlds, _ = play(steps, ticks=30)
    at = {w.tick: w for w in worlds}
    assert (at[9].ball_x, at[9].ball_y) != (1.0, 2.0)
    assert (at[10].ball_x, at[10].ball_y) == (1.0, 2.0), "the world frame of tick 10 shows the teleport"
    b1 = robot(at[10], "b", 1)
    assert (b1.x, b1.y) == (-2.0, -3.0) and math.isclose(b1.theta, 1.0)
    assert abs(robot(at[19], "a", 2).x) < 7 and abs(robot(at[20], "a", 2).x) > 7, "present = false parks it"


def test_by_force_rolls_the_ball_to_its_target():
    steps = (Step(at=0, actions=[RefereeOverride(command="STOP"), TeleportBall(x=0.0, y=3.0, by_force=True)]),)
    _, worlds, _ = play(steps, ticks=200)
    first, last = worlds[0], worlds[-1]
    assert (first.ball_x, first.ball_y) == (0.0, 0.0) and first.ball_vy > 0, "no jump: it rolls from where it lay"
    assert math.hypot(last.ball_x, last.ball_y - 3.0) < 0.15 and abs(last.ball_vy) < 1e-6


def test_a_condition_fires_once_when_it_first_holds():
    steps = (
        Step(at=0, actions=[RefereeOverride(command="STOP"), TeleportBall(x=0.0, y=0.0, vx=2.0, vy=0.0)]),
        Step(when=Condition(ball_in=Region(x0=1.0, y0=-1.0, x1=2.0, y1=1.0)), actions=[TeleportBall(x=-3.0, y=0.0)]),
    )
    _, worlds, _ = play(steps, ticks=100)
    jump = [w.tick for w in worlds if w.ball_x == -3.0]
    assert len(jump) == 1 and 20 < jump[0] < 40, jump
    assert max(w.ball_x for w in worlds if w.tick > jump[0]) < 0, "it fires once"


def test_a_forced_corner_is_the_set_piece_procedure():
    steps = (Step(at=0, actions=[RefereeOverride(command="CORNER", team="a")]),)
    summaries, worlds, refs = play(steps, ticks=150)
    log = [(e["tick"], e["command"], e["team"], e["cause"]) for e in summaries["referee"].extra["log"]]
    assert log[:3] == [(0, "STOP", "", "scenario"), (0, "CORNER", "a", "scenario"), (100, "START", "a", "clock")]
    corner = next(c for r in refs for c in r["commands"] if c["name"] == "CORNER")
    cfg = MatchConfig()
    assert (corner["x"], corner["y"]) == (cfg.field.length / 2 - 0.25, cfg.field.width / 2 - 0.25)
    w = {w.tick: w for w in worlds}[50]
    assert (w.ball_x, w.ball_y) == (corner["x"], corner["y"]), "the engine put the ball on the spot"


def test_a_forced_goal_counts_and_the_start_score_carries():
    steps = (Step(at=5, actions=[RefereeOverride(command="GOAL", team="b")]),)
    summaries, _, refs = play(steps, ticks=20, score=(2, 1), clock=100)
    assert summaries["referee"].extra["score"] == [2, 2]
    assert refs[0]["stage"] == "FIRST_HALF" and (refs[0]["score_a"], refs[0]["score_b"]) == (2, 1)


def test_half_time_comes_after_the_clock_already_played():
    cfg = MatchConfig(half_time=10.0, scenario=ScenarioParams(ticks=200, clock=400, stage="FIRST_HALF"))
    assert Rules.of(cfg).half_ticks == 100 and cfg.total_ticks == 200
    st, cmds = process(RefereeState(stage="FIRST_HALF"), Forced(7, RefereeOverride(command="HALF_TIME")), Rules.of(cfg))
    assert [c.name for c in cmds] == ["HALF_TIME", "SECOND_HALF", "KICKOFF"] and st.attack_dir_a == -1
    assert all(c.tick == 7 for c in cmds)


def test_steps_are_in_the_digest_and_reruns_are_identical():
    steps = (Step(at=0, actions=[RefereeOverride(command="START")]), Step(at=30, actions=[TeleportBall(x=2.0, y=1.0)]))
    a, _, _ = play(steps, ticks=80)
    b, _, _ = play(steps, ticks=80)
    c, _, _ = play(steps[:1], ticks=80)
    assert {k: s.digest for k, s in a.items()} == {k: s.digest for k, s in b.items()}
    assert a["engine"].digest != c["engine"].digest


def test_referee_steps_are_in_tick_order_and_the_config_round_trips():
    steps = (
        Step(at=50, actions=[RefereeOverride(command="STOP")]),
        Step(at=0, actions=[RefereeOverride(command="START"), TeleportBall(x=1.0)]),
    )
    assert [t for t, _ in referee_steps(steps)] == [0, 50]
    cfg = MatchConfig(scenario=ScenarioParams(ticks=10, stage="SECOND_HALF", steps=steps))
    assert MatchConfig.from_json(cfg.to_json()) == cfg
    assert not MatchConfig().scenario.active


@pytest.mark.parametrize(
    "bad",
    [dict(ticks=-1), dict(clock=30000), dict(stage="HALF_TIME"), dict(attack_dir_a=0)],
)
def test_bad_scenario_params_are_refused(bad):
    with pytest.raises(ConfigError, match="scenario"):
        MatchConfig(scenario=ScenarioParams(**bad)).validate()


def test_by_force_pushes_a_robot_from_where_it_stands():
    steps = (
        Step(at=0, actions=[RefereeOverride(command="STOP")]),
        Step(at=10, actions=[TeleportRobot(team="b", robot=2, x=0.0, y=-3.0, by_force=True)]),
    )
    _, worlds, _ = play(steps, ticks=20)
    at = {w.tick: w for w in worlds}
    before, after = robot(at[9], "b", 2), robot(at[10], "b", 2)
    assert (after.x, after.y) == (before.x, before.y), "no jump"
    assert after.vy < -2.0 and abs(after.vx) < abs(after.vy), "moving towards the target"


def test_a_link_step_changes_every_receiver_s_links_from_its_tick_on():
    from arena.schemas.messages import SetLink

    start = Step(at=0, actions=[RefereeOverride(command="START")])
    lossy = SetLink(preset="wifi", overrides={"wifi": {"loss_good": 0.5}, "sensor": {"loss_good": 0.5}})
    plain, _, _ = play((start,), ticks=100)
    late, _, _ = play((start, Step(at=10_000, actions=[lossy])), ticks=100)
    changed, _, _ = play((start, Step(at=50, actions=[lossy])), ticks=100)
    assert {k: s.digest for k, s in late.items()} == {k: s.digest for k, s in plain.items()}, (
        "no effect before its tick"
    )
    assert changed["engine"].digest != plain["engine"].digest
    dropped = sum(s.links.get("wifi", {}).get("dropped", 0) for s in changed.values())
    assert dropped > 0 and sum(s.links.get("wifi", {}).get("dropped", 0) for s in plain.values()) == 0


def test_the_link_emulator_switches_models_at_the_tick():
    import random

    from arena.runtime.links import LinkEmulator, LinkModel

    e = LinkEmulator(LinkModel(), random.Random(1), changes=((5, LinkModel(loss_good=1.0)),))
    assert [e.decide(k) for k in range(8)] == [0.0] * 5 + [None] * 3


def test_conditions_on_a_command_a_robot_and_possession():
    corner = Step(at=0, actions=[RefereeOverride(command="CORNER", team="a")])
    on_corner = Step(when=Condition(command="CORNER"), actions=[TeleportRobot(team="b", robot=2, x=-1.0, y=-1.0)])
    on_robot = Step(
        when=Condition(robot="b/2", robot_in=Region(x0=-1.1, y0=-1.1, x1=-0.9, y1=-0.9)),
        actions=[TeleportRobot(team="b", robot=1, x=-2.0, y=-2.0)],
    )
    never = Step(when=Condition(possession="b"), actions=[TeleportBall(x=-5.0, y=0.0)])
    _, worlds, _ = play((corner, on_corner, on_robot, never), ticks=20)
    first = {w.tick for w in worlds if (robot(w, "b", 2).x, robot(w, "b", 2).y) == (-1.0, -1.0)}
    second = {w.tick for w in worlds if (robot(w, "b", 1).x, robot(w, "b", 1).y) == (-2.0, -2.0)}
    assert first and second and min(second) == min(first) + 1, (first, second)
    assert all(w.ball_x != -5.0 for w in worlds), "nobody of b held the ball: that step never fired"


def test_a_killed_robot_process_is_found_dead_parked_and_repaired_out():
    from arena.schemas.messages import KillProcess

    steps = (
        Step(at=0, actions=[RefereeOverride(command="START")]),
        Step(at=50, actions=[KillProcess(process="robot/b/1")]),
    )
    summaries, worlds, _ = play(steps, ticks=100)
    assert summaries["robot/b/1"].tick < 50 <= summaries["robot/b/2"].tick
    assert "robot/b/1" in summaries["engine"].dead and "b/1" in summaries["engine"].extra["parked"]
    log = [(e["command"], e.get("robot")) for e in summaries["referee"].extra["log"]]
    assert ("REPAIR_OUT", 1) in log
    assert abs(robot(worlds[-1], "b", 1).x) > 7


def _inbox(kinds):
    """An OperatorInbox on a memory bus (which carries no MACs: the zenoh path is
    tests/integration/test_strangers.py), and what puts on its key."""
    import logging
    import types

    from arena.runtime.lockstep import Rejections
    from arena.runtime.mac import Keyring
    from arena.runtime.transport import MemoryBus, MemoryTransport
    from arena.schemas.keys import Keys
    from arena.sim.director import OperatorInbox

    bus = MemoryBus()
    rejections = Rejections(logging.getLogger("t"))
    node = types.SimpleNamespace(
        keys=Keys("m"), cfg=MatchConfig(), rejections=rejections, transport=MemoryTransport(bus),
        mac_check=lambda key, sender: (Keyring("engine").verifier(sender, key), lambda: rejections.forged(key, sender)),
    )  # fmt: skip
    return OperatorInbox(node, kinds), MemoryTransport(bus).publisher("arena/m/operator"), node.rejections


@pytest.mark.parametrize(
    ("action", "why"),
    [
        (TeleportBall(x=math.nan, y=0.0), "x is not finite"),
        (TeleportBall(x=1e308, y=0.0), "x = 1e+308 is beyond +-7"),
        (TeleportBall(x=0.0, y=5.5), "y = 5.5 is beyond +-5"),
        (TeleportBall(x=0.0, y=0.0, vx=30.0, vy=0.0), "ball speed 30 is above the model's 13"),
        (TeleportBall(x=0.0, y=0.0, z=50.0), "z = 50 is beyond"),
        (TeleportRobot(team="a", robot=0, x=0.0, y=0.0, vx=6.0, vy=0.0), "speed 6 is above the model's 5"),
        (TeleportRobot(team="a", robot=0, omega=math.inf), "omega is not finite"),
        (TeleportRobot(team="a", robot=7, x=0.0, y=0.0), "robot 7: the match has 3 per team"),
        (TeleportRobot(team="a", robot=0, orientation=1e308), "orientation = 1e+308"),
        (RefereeOverride(command="FREEKICK", team="a", x=math.nan), "x is not finite"),
    ],
)
def test_an_action_out_of_range_is_refused_with_its_reason_counted_and_the_rest_applies(action, why):
    """A NaN from a stranger, or 1e308 from the real operator, reached the physics, and the match's own
    recording then failed review."""
    from arena.sim.director import check_action

    assert why in check_action(MatchConfig(), action)
    inbox, put, rejections = _inbox((TeleportBall, TeleportRobot, RefereeOverride))
    good = TeleportBall(x=1.0, y=-1.0, vx=0.0, vy=0.0)
    put(msgspec.msgpack.encode(Operator(seq=5, actions=[action, good])))
    assert inbox.take(3) == [good]
    assert rejections.by_reason == {"invalid": 1}
    assert [(r["tick"], r["why"]) for r in inbox.refused] == [(3, check_action(MatchConfig(), action))]
    assert inbox.summary()["operator"] == [{"tick": 3, "seq": 5, "action": msgspec.to_builtins(good)}]


def test_a_frame_put_again_is_refused_as_out_of_sequence():
    inbox, put, rejections = _inbox((TeleportBall,))
    frame = msgspec.msgpack.encode(Operator(seq=7, actions=[TeleportBall(x=1.0, y=1.0)]))
    put(frame)
    put(frame)  # a genuine frame, MAC and all, put again by whoever saw it
    assert len(inbox.take(0)) == 1 and rejections.by_reason == {"out-of-sequence": 1}


def test_a_scenario_step_out_of_range_is_refused_by_the_engine_and_the_match_goes_on():
    """A configuration made by hand (not through the scenario loader) reaches the engine as it is."""
    cfg = MatchConfig(
        half_time=0.2,
        scenario=ScenarioParams(steps=(Step(at=2, actions=(TeleportBall(x=math.inf, y=0.0),)),)),
    )
    summaries, _ = play_in_process(cfg)
    engine = summaries["engine"]
    assert engine.rejected_reasons == {"invalid": 1} and engine.tick == cfg.total_ticks
