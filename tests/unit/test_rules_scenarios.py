"""The rules end to end on the real engine physics: Physics + the rules' Restarts + RefereeBox.

No robots think here: the test moves them and the ball, the physics reports
ball events, the referee box decides, and `Restarts` (rules/setpieces.py) applies the
commands (ball spots, stoppages, legal positions at START), in the engine's
order: every referee period the box sees the events so far and its frame is
applied before the next physics step.
"""

from __future__ import annotations

import math

import pytest

from arena.config import MatchConfig, RulesParams
from arena.rules.referee_box import RefereeBox
from arena.rules.setpieces import Restarts
from arena.schemas.messages import BallEvent, Cmd, RefCommand
from arena.sim.physics import Physics, StuckWatch

CFG = MatchConfig(half_time=20.0, robots=3)
F = CFG.field
FACE = CFG.robot.size / 2 + CFG.ball.radius  # [m] robot centre to a touching ball's centre
PARK_Y = -F.width / 2 - 0.6  # [m] robots not in a scene wait in the -y run-off


class Match:
    """The engine's side of a match without robot processes, stepped by the test."""

    def __init__(self, cfg: MatchConfig = CFG):
        self.cfg = cfg
        self.ph = Physics(cfg)
        self.ph.kickoff_positions("a")
        self.ph.stop_play()
        self.box = RefereeBox(cfg)
        self.restarts = Restarts(cfg, self.ph)
        self.stuck = StuckWatch(cfg)
        self.k = 0
        self.events = []
        self.commands: list[RefCommand] = []

    def step(self) -> None:
        if self.k % self.cfg.timing.referee_period == 0:
            self.events += self.stuck.check(self.ph)  # as the engine does before it sends its events
            cmds = self.box.step(self.k, self.events)
            self.events = []
            self.commands += cmds
            self.restarts.apply_frame(self.box.frame(self.k, cmds))
        self.events += self.ph.step()
        self.k += 1

    def run(self, seconds: float) -> None:
        for _ in range(int(round(seconds / self.cfg.timing.dt))):
            self.step()

    def run_until(self, what, seconds: float = 30.0) -> None:
        for _ in range(int(round(seconds / self.cfg.timing.dt))):
            if what():
                return
            self.step()
        raise AssertionError(f"not within {seconds} s; commands {[(c.name, c.team) for c in self.commands]}")

    def in_play(self) -> bool:
        return self.box.state.in_play and self.ph.in_play

    def since(self, n: int) -> list[tuple[str, str]]:
        return [(c.name, c.team) for c in self.commands[n:]]

    def park_all(self) -> None:
        for i, (team, n) in enumerate(self.ph.robot_ids):
            self.ph.place_robot(team, n, -5.5 + 1.1 * i, PARK_Y, 0.0)

    def drive(self, team: str, n: int, **cmd) -> None:
        self.ph.set_command(team, n, Cmd(tick=self.k, **cmd))

    def kick_from(self, team: str, n: int, x: float, y: float, heading: float, speed: float) -> None:
        """Robot n stands at (x, y) behind the ball and kicks it along `heading`."""
        self.ph.place_robot(team, n, x, y, heading)
        self.ph.place_ball(x + (FACE + 0.02) * math.cos(heading), y + (FACE + 0.02) * math.sin(heading))
        self.drive(team, n, kick_speed=speed)


def playing() -> Match:
    m = Match()
    m.run_until(m.in_play)
    m.park_all()
    return m


def test_ball_over_the_touch_line_gives_the_throw_in_to_the_other_team_where_it_crossed():
    m = playing()
    n = len(m.commands)
    m.kick_from("a", 1, 1.5, 2.0, math.pi / 2, 3.0)
    m.run_until(lambda: not m.in_play())
    assert m.since(n) == [("STOP", ""), ("THROWIN", "b")]
    throw_in = m.commands[-1]
    assert (throw_in.x, throw_in.y) == (pytest.approx(1.5, abs=0.02), F.width / 2)
    m.step()
    assert m.ph.ball_state()[:2] == pytest.approx((throw_in.x, throw_in.y), abs=1e-9), "the engine put it there"
    m.run_until(m.in_play, CFG.rules.setpiece_time + 0.2)
    assert m.since(n)[-1] == ("START", "b")


def test_a_goal_in_the_second_half_counts_for_the_right_team_after_the_switch():
    m = playing()
    m.run_until(lambda: m.box.state.stage == "SECOND_HALF" and m.in_play(), 25.0)
    assert m.box.state.attack_dir_a == -1 and m.ph.attack_dir_a == -1
    m.park_all()
    n = len(m.commands)
    m.kick_from("a", 1, -3.0, 0.3, math.pi, 6.0)  # a now attacks the -x goal
    m.run_until(lambda: not m.in_play())
    assert m.since(n) == [("GOAL", "a"), ("STOP", ""), ("KICKOFF", "b")]
    assert m.box.state.score == (1, 0)
    m.run_until(m.in_play)
    m.park_all()
    m.kick_from("a", 2, 3.0, -0.3, 0.0, 6.0)  # into its own (+x) goal: b's goal
    m.run_until(lambda: not m.in_play())
    assert m.box.state.score == (1, 1)
    assert m.since(n)[-3:] == [("GOAL", "b"), ("STOP", ""), ("KICKOFF", "a")]


@pytest.mark.parametrize(
    ("kicker", "want", "spot"),
    [(("a", 1), ("GOALKICK", "b"), (5.5, 1.5)), (("b", 1), ("CORNER", "a"), (5.75, 3.75))],
    ids=["attacker-last-goal-kick", "defender-last-corner"],
)
def test_ball_over_the_goal_line_beside_the_goal(kicker, want, spot):
    m = playing()
    n = len(m.commands)
    m.kick_from(*kicker, 3.0, 2.5, 0.0, 5.0)  # +x: b's goal line in the first half
    m.run_until(lambda: not m.in_play())
    assert m.since(n) == [("STOP", ""), want]
    assert (m.commands[-1].x, m.commands[-1].y) == pytest.approx(spot)


def test_driving_into_an_opponent_gives_a_free_kick_to_the_other_team():
    m = playing()
    n = len(m.commands)
    m.ph.place_robot("b", 2, 1.0, 1.0, math.pi)
    m.ph.place_robot("a", 2, -1.0, 1.0, 0.0)
    m.drive("a", 2, vx=3.0)
    m.run_until(lambda: not m.in_play())
    assert m.since(n) == [("STOP", ""), ("FREEKICK", "b")]
    assert (m.commands[-1].x, m.commands[-1].y) == pytest.approx((0.775, 1.0), abs=0.25)


def test_dribbling_past_three_metres_gives_a_free_kick_to_the_other_team():
    m = playing()
    n = len(m.commands)
    m.ph.place_robot("b", 1, 1.5, 0.0, math.pi)
    m.ph.place_ball(1.5 - FACE - 0.02, 0.0)
    m.drive("b", 1, vx=1.5, dribbler=True)
    m.run_until(lambda: not m.in_play())
    assert m.since(n) == [("STOP", ""), ("FREEKICK", "a")]
    assert m.commands[-1].x == pytest.approx(1.5 - FACE - CFG.rules.dribble_limit, abs=0.1)


def test_an_opponent_too_close_at_start_is_placed_at_the_set_piece_distance():
    m = playing()
    m.kick_from("a", 1, 1.5, 2.0, math.pi / 2, 3.0)
    m.run_until(lambda: m.box.state.command == "THROWIN")
    m.step()
    spot = m.ph.ball_state()[:2]
    m.ph.place_robot("a", 2, spot[0] + 0.6, spot[1] - 0.5, 0.0)  # a may not stay: b throws in
    m.ph.place_robot("b", 2, spot[0] - 0.6, spot[1] - 0.5, 0.0)  # the taking team may
    m.run_until(m.in_play)
    a2, b2 = m.ph.robot_pose("a", 2), m.ph.robot_pose("b", 2)
    assert math.hypot(a2[0] - spot[0], a2[1] - spot[1]) == pytest.approx(CFG.rules.setpiece_distance + 0.05)
    assert (b2[0], b2[1]) == pytest.approx((spot[0] - 0.6, spot[1] - 0.5))
    assert m.restarts.placed[-1][1:3] == ("a", 2) and len(m.restarts.placed) == 1


def test_a_set_piece_not_taken_in_time_becomes_a_drop_ball_on_its_spot():
    m = playing()
    m.kick_from("a", 1, 1.5, 2.0, math.pi / 2, 3.0)
    m.run_until(lambda: m.box.state.command == "THROWIN")
    n = len(m.commands)
    spot = (m.commands[-1].x, m.commands[-1].y)
    m.ph.place_robot("a", 1, 0.0, PARK_Y, 0.0)
    m.drive("a", 1)
    m.run_until(lambda: m.box.state.command == "DROP_BALL", CFG.rules.setpiece_time + CFG.rules.take_time + 0.5)
    assert m.since(n) == [("START", "b"), ("STOP", ""), ("DROP_BALL", "")]
    assert (m.commands[-1].x, m.commands[-1].y) == spot
    start, drop = m.commands[n], m.commands[-1]
    assert (drop.tick - start.tick) * CFG.timing.dt == pytest.approx(CFG.rules.take_time, abs=0.1)


def test_a_taken_set_piece_plays_on():
    m = playing()
    m.kick_from("a", 1, 1.5, 2.0, math.pi / 2, 3.0)
    m.run_until(lambda: m.box.state.command == "THROWIN")
    m.step()
    bx, by, *_ = m.ph.ball_state()
    m.ph.place_robot("b", 1, bx, by + FACE + 0.05, -math.pi / 2)
    m.run_until(m.in_play)
    n = len(m.commands)
    m.drive("b", 1, vx=0.3)
    m.run(CFG.rules.take_time + 1.0)
    assert m.since(n) == [] and m.box.state.take_by == -1


def test_no_progress_gives_a_drop_ball():
    m = Match(CFG.replace(rules=RulesParams(no_progress_s=2.0)))
    m.run_until(m.in_play)
    m.park_all()
    n = len(m.commands)
    m.kick_from("a", 1, -1.0, 1.0, 0.0, 0.5)  # a touch: the kickoff is taken, then the ball lies still
    m.run_until(lambda: not m.in_play(), 3.0)
    assert m.since(n) == [("STOP", ""), ("DROP_BALL", "")]


# ------------------------------------------- penalty, cards, repair, end (issue 17)
def _push(m: Match, offender: tuple[str, int], victim: tuple[str, int], x: float, y: float) -> None:
    """`offender` drives from x + 1.3 (facing -x) into `victim`, standing still at (x, y)."""
    m.ph.place_robot(*victim, x, y, 0.0)
    m.ph.place_robot(*offender, x + 1.3, y, math.pi)
    m.drive(*offender, vx=3.0)


def _in_area(x: float, y: float, side: int) -> bool:
    reach = CFG.robot.size * math.sqrt(0.5)
    return side * x > F.length / 2 - F.penalty_area_depth - reach and abs(y) < F.penalty_area_width / 2 + reach


def test_a_foul_by_a_defender_in_its_own_area_gives_a_penalty_with_the_procedure():
    m = playing()  # first half: b defends the +x goal
    n = len(m.commands)
    _push(m, ("b", 2), ("a", 2), 5.0, 1.8)  # contact near x = 5.2: inside b's penalty area
    m.run_until(lambda: not m.in_play())
    assert m.since(n) == [("STOP", ""), ("PENALTY", "a")]
    mark = (F.length / 2 - F.penalty_mark_distance, 0.0)
    assert (m.commands[-1].x, m.commands[-1].y) == pytest.approx(mark)
    for when in ("at PENALTY", "at START"):
        if when == "at START":
            m.ph.place_robot("b", 1, 5.0, -1.0, 0.0)  # walks into the area while the teams position
            m.run_until(m.in_play, CFG.rules.setpiece_time + 0.2)
            assert m.since(n)[-1] == ("START", "a")
        else:
            m.step()
        assert m.ph.ball_state()[:2] == pytest.approx(mark, abs=1e-6), when
        poses = {(t, k): (x, y) for t, k, x, y, *_ in m.ph.robot_states()}
        assert poses[("b", 0)] == pytest.approx((F.length / 2 - CFG.robot.size / 2, 0.0), abs=0.01), when
        assert poses[("a", 2)] == pytest.approx((mark[0] - 0.5, 0.0), abs=0.01), f"the taker, {when}"
        for r, (x, y) in poses.items():
            if r not in (("b", 0), ("a", 2)):
                assert not _in_area(x, y, 1), f"{r} in the area {when}"
                assert math.hypot(x - mark[0], y) >= CFG.rules.setpiece_distance - 1e-6, f"{r} {when}"


def test_repeated_fouls_by_one_robot_give_cards_and_a_double_yellow_sends_it_off():
    cfg = MatchConfig(half_time=20.0, robots=3, rules=RulesParams(yellow_fouls=1))  # 1st foul yellow, 2nd double
    m = Match(cfg)
    cards = []
    for i in range(2):
        m.run_until(m.in_play)
        m.park_all()
        n = len(m.commands)
        _push(m, ("a", 1), ("b", 2), -1.0 + i, 1.0)
        m.run_until(lambda: not m.in_play())
        cards += [c for c in m.commands[n:] if c.name.endswith(("CARD", "YELLOW"))]
    assert [(c.name, c.team, c.robot) for c in cards] == [("YELLOW_CARD", "a", 1), ("DOUBLE_YELLOW", "a", 1)]
    m.step()
    assert ("a", 1) in m.ph.parked() and m.box.state.off == (("a", 1),)
    x, y = m.ph.robot_pose("a", 1)[:2]
    assert abs(x) > F.length / 2 + F.runoff or abs(y) > F.width / 2 + F.runoff, "beyond the fence"
    assert [s[1:] for s in m.restarts.sent_off] == [("a", 1, "DOUBLE_YELLOW")]
    m.run_until(m.in_play, CFG.rules.setpiece_time + 0.2)  # play goes on, a short-handed
    m.run(1.0)
    assert ("a", 1) in m.ph.parked() and m.ph.robot_pose("a", 1)[:2] == pytest.approx((x, y))


def test_a_dead_robot_is_taken_off_with_repair_out_and_play_goes_on():
    m = playing()
    n = len(m.commands)
    m.events.append(BallEvent(kind="ROBOT_DEAD", tick=m.k, team="b", robot=1))  # as the engine reports it
    m.run(0.3)
    assert m.since(n) == [("REPAIR_OUT", "b")] and m.commands[-1].robot == 1
    assert ("b", 1) in m.ph.parked() and m.in_play()


def test_a_robot_driven_into_the_fence_is_stuck_and_taken_off_with_repair_out():
    cfg = MatchConfig(half_time=20.0, robots=3, rules=RulesParams(stuck_s=2.0))
    m = Match(cfg)
    m.run_until(m.in_play)
    m.park_all()
    n = len(m.commands)
    fence_y = F.width / 2 + F.runoff
    m.ph.place_robot("a", 2, 2.0, fence_y - 0.4, math.pi / 2)  # facing the fence, 0.4 m from it
    m.ph.place_robot("b", 2, -2.0, 0.0, 0.0)  # driven freely round the field: never stuck
    m.drive("a", 2, vx=1.0)
    for _ in range(int(round(2.8 / cfg.timing.dt))):
        m.drive("b", 2, vx=1.0, omega=1.0)
        m.step()
    assert m.since(n) == [("REPAIR_OUT", "a")] and m.commands[-1].robot == 2
    assert m.ph.parked() == [("a", 2)] and m.in_play(), "taken off; play goes on"
    assert m.box.log[-1].cause == "robot_stuck a/2"


def test_the_match_ends_with_end_game_park_and_gameover_and_play_stops():
    cfg = MatchConfig(half_time=1.0, robots=1)
    m = Match(cfg)
    m.run(2 * cfg.half_time + 0.2)
    assert [c.name for c in m.commands[-3:]] == ["END_GAME", "PARK", "GAMEOVER"]
    assert m.commands[-1].tick == cfg.total_ticks and not m.ph.in_play
