"""Issue 19 part 5: the trajectory and heatmap pictures' data (review/plots.py)."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.colors import to_rgb

from arena.config import MatchConfig
from arena.review import plots
from arena.schemas.messages import RobotState, World

CFG = MatchConfig(half_time=1.0)  # 50 ticks a half


def world(tick: int, a0=(-5.0, 0.0), a1=(-1.0, 1.0), b1=(2.0, -1.0), ball=(0.5, 0.25)) -> World:
    robots = [
        RobotState(team="a", robot=0, x=a0[0], y=a0[1], theta=0.0),
        RobotState(team="a", robot=1, x=a1[0], y=a1[1], theta=0.0),
        RobotState(team="b", robot=1, x=b1[0], y=b1[1], theta=0.0),
    ]
    return World(tick=tick, t=tick * 0.02, ball_x=ball[0], ball_y=ball[1], robots=robots)


def test_every_robot_has_its_own_colour_and_marker_in_its_teams_hue():
    colours = {(t, n): to_rgb(plots.robot_colour(t, n)) for t in "ab" for n in range(6)}
    others = [to_rgb(c) for c in (plots.BALL, "#2e7d32", "white")]  # ball, grass, lines
    everything = [*colours.values(), *others]
    gaps = [math.dist(p, q) for i, p in enumerate(everything) for q in everything[i + 1 :]]
    assert min(gaps) >= 0.25, "every robot's colour is clearly apart from every other, the grass, lines and ball"
    for (t, n), (r, _, b) in colours.items():
        assert (b > r) if t == "a" else (r > b), f"{t}/{n}: team a blue, team b magenta/red"
    assert len({plots.robot_marker(n) for n in range(6)}) == 6


def test_heatmap_shares_one_light_to_dark_scale_and_leaves_empty_cells_transparent():
    grids = [(np.array([[np.nan, 0.1], [2.0, np.nan]]),), (np.array([[40.0, np.nan]]),)]
    norm = plots.shared_norm(grids)
    assert (norm.vmin, norm.vmax) == (0.1, 40.0), "one scale over every panel"
    cmap = plots.colour_map()
    assert cmap(np.ma.masked_invalid([np.nan]))[0][3] == 0.0, "a cell nobody visited shows the field"
    least, most = cmap(norm(0.1)), cmap(norm(40.0))
    assert sum(least[:3]) > 2.4 and sum(most[:3]) < 1.2, "a moment is light, much time dark: no black holes"


def test_tracks_split_by_half_and_break_at_a_placement():
    worlds = [world(k, a1=(-1.0 + 0.01 * k, 1.0)) for k in range(40)]
    worlds += [world(k, a1=(3.0, 3.0)) for k in range(40, 50)]  # placed: a 4 m jump
    worlds += [world(k, a1=(-3.0, 0.0)) for k in range(50, 100)]
    first, _ = plots.split_tracks(worlds, 0, CFG.half_ticks)
    xs, _ = first["a/1"]
    assert len(xs) == 51 and math.isnan(xs[40]), "the jump is a gap, not a line"
    second, ball = plots.split_tracks(worlds, CFG.half_ticks, 2 * CFG.half_ticks + 1)
    assert second["a/1"][0] == [-3.0] * 50 and len(ball[0]) == 50


def test_heatmap_points_attack_to_the_right_in_both_halves_and_leave_out_goalkeepers():
    worlds = [world(10), world(60)]  # first half, second half
    xs, ys = plots.mirrored_points(worlds, CFG, "a", goalkeepers=False)
    assert list(xs) == [-1.0, 1.0] and list(ys) == [1.0, -1.0]
    xs, _ = plots.mirrored_points(worlds, CFG, "a", goalkeepers=True)
    assert sorted(xs) == [-5.0, -1.0, 1.0, 5.0]
    xs, _ = plots.mirrored_points(worlds, CFG, "b", goalkeepers=False)
    assert list(xs) == [-2.0, 2.0], "team b attacks -x in the first half: mirrored there"
    xs, ys = plots.mirrored_points(worlds, CFG, "", goalkeepers=False)
    assert np.allclose(xs, [0.5, -0.5]) and np.allclose(ys, [0.25, -0.25])


def test_the_heatmap_cell_grows_for_a_short_match():
    """A 2 x 60 s match's ball path (about 120 m over a 140 m^2 fenced area) visited 27 % of
    the 0.5 m cells, a patchwork of single strokes: the cell follows the amount of play."""
    import numpy as np

    from arena.review.plots import MAX_CELL, MIN_CELL, cell_size

    def path(metres: float, step: float = 0.05):  # back and forth along x within the field
        s = np.arange(0.0, metres, step)
        return np.abs((s % 24.0) - 12.0) - 6.0, np.zeros_like(s)

    assert cell_size(*path(122.0), 140.0) == 1.25  # 140 / 122 = 1.15, up to the next quarter metre
    assert cell_size(*path(617.0), 140.0) == MIN_CELL  # a 2 x 300 s match keeps the fine grid
    assert cell_size(*path(10.0), 140.0) == MAX_CELL
    xs, ys = path(122.0)
    xs[100:200] = np.nan  # frames without a ball, and a placement, count no path
    xs[300] += 5.0
    assert cell_size(xs, ys, 140.0) == 1.25
