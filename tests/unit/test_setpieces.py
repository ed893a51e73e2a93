"""Set-piece geometry (rules/setpieces.py): ball spots, who keeps away, where a robot is put."""

from __future__ import annotations

import math

import pytest

from arena.config import MatchConfig
from arena.rules import setpieces as sp

CFG = MatchConfig()
F, R = CFG.field, CFG.rules


@pytest.mark.parametrize(
    ("spot", "x", "y", "want"),
    [
        (sp.throw_in_spot, 2.0, 4.15, (2.0, 4.0)),
        (sp.throw_in_spot, -6.3, -4.2, (-5.5, -4.0)),
        (sp.corner_spot, 6.2, 3.0, (5.75, 3.75)),
        (sp.corner_spot, -6.2, -0.1, (-5.75, -3.75)),
        (sp.goal_kick_spot, 6.2, -2.0, (5.5, -1.5)),
        (sp.goal_kick_spot, -6.2, 0.5, (-5.5, 1.5)),
        (sp.free_kick_spot, 0.3, -2.0, (0.3, -2.0)),
        (sp.free_kick_spot, 5.0, -1.0, (4.5, -1.0)),  # out of the penalty area
        (sp.free_kick_spot, 5.0, 3.9, (5.0, 3.5)),  # beside it: only kept inside the lines
        (sp.drop_ball_spot, 6.3, -3.95, (5.0, -3.0)),
    ],
)
def test_ball_spots(spot, x, y, want):
    assert spot(x, y, CFG) == pytest.approx(want)


@pytest.mark.parametrize(
    ("x", "attack_dir_a", "defender"),
    [(6.1, 1, "b"), (-6.1, 1, "a"), (6.1, -1, "a"), (-6.1, -1, "b")],
)
def test_defender_of_goal_line(x, attack_dir_a, defender):
    assert sp.defender_of_goal_line(x, attack_dir_a) == defender


@pytest.mark.parametrize(
    ("command", "team", "distance", "teams"),
    [
        ("THROWIN", "a", R.setpiece_distance, ("b",)),
        ("FREEKICK", "b", R.setpiece_distance, ("a",)),
        ("CORNER", "a", R.setpiece_distance, ("b",)),
        ("GOALKICK", "b", R.setpiece_distance, ("a",)),
        ("DROP_BALL", "", R.drop_ball_distance, ("a", "b")),
        ("KICKOFF", "a", F.center_circle_radius + CFG.robot.size / 2, ("b",)),
    ],
)
def test_keep_away(command, team, distance, teams):
    assert sp.keep_away(command, team, CFG) == sp.KeepAway(distance, teams)
    assert R.setpiece_distance >= 2.0


def test_too_close_names_opponents_only_and_spares_the_keeper_in_its_area():
    robots = [
        ("a", 1, 1.5, 0.0),  # taking team: may stand close
        ("b", 1, 1.5, 0.0),  # opponent 1.5 m away: too close
        ("b", 2, 3.1, 0.0),  # 2.1 m: fine
        ("b", 0, 5.6, 0.3),  # keeper in its own penalty area (b defends +x): exempt
    ]
    assert sp.too_close(robots, "FREEKICK", "a", (0.0, 0.0), 1, CFG) == [("b", 1)]
    near_goal = [("b", 0, 5.6, 0.3)]
    assert sp.too_close(near_goal, "FREEKICK", "a", (4.5, 0.0), 1, CFG) == []
    assert sp.too_close(near_goal, "FREEKICK", "a", (4.5, 0.0), -1, CFG) == [("b", 0)]  # not its own area now


def test_legal_spot_is_the_nearest_free_place_outside_the_distance():
    spot = (0.0, 0.0)
    x, y = sp.legal_spot(1.0, 0.0, spot, 2.0, [], CFG)
    assert (x, y) == pytest.approx((2.0 + sp.PLACE_MARGIN, 0.0))
    # that place is taken: the next one round the ring, still at the distance
    x, y = sp.legal_spot(1.0, 0.0, spot, 2.0, [(2.05, 0.0)], CFG)
    assert math.hypot(x, y) == pytest.approx(2.0 + sp.PLACE_MARGIN)
    assert math.hypot(x - 2.05, y) >= 2 * CFG.robot.size * math.sqrt(0.5)


def test_legal_spot_stays_inside_the_fence_and_out_of_the_goals():
    reach = CFG.robot.size * math.sqrt(0.5)
    for spot in [(5.75, 3.75), (5.5, 0.0), (-6.0, -4.0), (0.0, 4.0)]:
        for angle in range(0, 360, 30):
            rx = spot[0] + 0.5 * math.cos(math.radians(angle))
            ry = spot[1] + 0.5 * math.sin(math.radians(angle))
            x, y = sp.legal_spot(rx, ry, spot, 2.0, [], CFG)
            assert math.hypot(x - spot[0], y - spot[1]) >= 2.0
            assert abs(x) <= F.length / 2 + F.runoff - reach and abs(y) <= F.width / 2 + F.runoff - reach
            assert not (abs(x) > F.length / 2 - reach and abs(y) < F.goal_width / 2 + reach)
