"""The trajectory and heatmap pictures of `arena review --plots` (plots a team can read).

* One colour and one marker per robot: team a's colours are blues, cyans and
  teals, team b's magentas, reds and oranges (the MSL cyan and magenta), so a
  robot's team shows at a glance and its number by hue and marker; the
  goalkeeper is a dark square. Up to six per team.
* Trajectories: one panel per half, since the teams change ends at half time;
  a placement (a jump between two frames: a restart, a robot parked off the
  field) breaks the line instead of drawing it across the field.
* Heatmaps: coordinates mirrored so that every panel's team attacks towards +x
  in both halves (the ball: team a's direction), a colour bar in seconds per
  cell, and the goalkeepers left out unless asked for (they stand in one cell
  for the whole match and drown everyone else). One logarithmic colour scale for
  all three panels, light for little time and dark for much, so a rarely visited
  cell never looks like a hole; a cell nobody visited is transparent.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from arena.recording.analysis.review import JUMP
from arena.schemas.messages import World

# Robot number n of each team: goalkeeper (0) first. Colour-blind-safe pairs from the ColorBrewer and
# Tableau palettes, each team's within its own hue family; every colour at least 0.25 apart (RGB, 0..1) from
# every other, from the grass, the white lines and the orange ball.
TEAM_PALETTES = {
    "a": ("#08306b", "#1f78b4", "#17becf", "#00897b", "#7fb8e6", "#0000ff"),
    "b": ("#7a0177", "#e7298a", "#d62728", "#f7a1c4", "#a6761d", "#67001f"),
}
MARKERS = ("s", "o", "^", "D", "v", "8")  # goalkeeper square, then circle, triangle, diamond, ..., octagon
BALL = "#ff8c00"
MARK_EVERY = 5.0  # [s] of play between two markers on a trajectory
HEAT_MAP = "YlOrRd"  # light yellow (a moment) to dark red (much time): nothing reads as a hole on the grass


def robot_colour(team: str, number: int) -> str:
    """The robot's own colour, in its team's hue family."""
    palette = TEAM_PALETTES[team]
    return palette[number % len(palette)]


def robot_marker(number: int) -> str:
    """The robot's marker: the same shape for the same number in both teams."""
    return MARKERS[number % len(MARKERS)]


def split_tracks(worlds: list[World], first_tick: int, last_tick: int) -> tuple[dict[str, tuple], tuple]:
    """Per robot and for the ball, (xs, ys) over ticks [first_tick, last_tick), NaN at every jump."""
    tracks: dict[str, tuple[list[float], list[float]]] = {}
    ball: tuple[list[float], list[float]] = ([], [])
    for w in worlds:
        if not first_tick <= w.tick < last_tick:
            continue
        _extend(ball, w.ball_x, w.ball_y)
        for r in w.robots:
            _extend(tracks.setdefault(f"{r.team}/{r.robot}", ([], [])), r.x, r.y)
    return dict(sorted(tracks.items())), ball


def _extend(track: tuple[list[float], list[float]], x: float, y: float) -> None:
    xs, ys = track
    if xs and not math.isnan(xs[-1]) and math.hypot(x - xs[-1], y - ys[-1]) > JUMP:
        xs.append(math.nan)
        ys.append(math.nan)
    xs.append(x)
    ys.append(y)


def trajectories(worlds: list[World], cfg, path: Path, draw_field) -> str:
    """trajectories.png: first and second half side by side, one colour and marker per robot.

    A marker every MARK_EVERY seconds of play on each track: its spacing shows the robot's speed."""
    import matplotlib.pyplot as plt

    half = cfg.half_ticks
    fig, axes = plt.subplots(1, 2, figsize=(18, 7.2))
    for ax, (title, lo, hi, a_dir) in zip(axes, (("first half", 0, half, 1), ("second half", half, 2 * half + 1, -1))):
        draw_field(ax, cfg)
        tracks, ball = split_tracks(worlds, lo, hi)
        every = max(1, round(MARK_EVERY / (cfg.timing.dt * _frame_ticks(worlds))))
        for name, (xs, ys) in tracks.items():
            team, n = name.split("/")
            label = name + (" (GK)" if n == "0" else "")
            style = {"color": robot_colour(team, int(n)), "marker": robot_marker(int(n)), "markevery": every}
            ax.plot(xs, ys, lw=1.1, ms=5, mec="black", mew=0.4, label=label, **style)
        ax.plot(ball[0], ball[1], color=BALL, lw=0.8, ls=(0, (3, 1.5)), label="ball")
        right, left = "\u2192", "\u2190"
        a_arrow, b_arrow = (right, left) if a_dir > 0 else (left, right)
        ax.set_title(f"{title}: a attacks {a_arrow}, b attacks {b_arrow}")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=10, frameon=False)
    fig.suptitle(f"trajectories: {cfg.home} (a) vs {cfg.away} (b), seed {cfg.seed}")
    fig.tight_layout(rect=(0, 0.06, 1, 1))  # room for the legend below the panels
    return _save(fig, path)


def _frame_ticks(worlds: list[World]) -> int:
    """Ticks between two recorded world frames."""
    return max(1, worlds[1].tick - worlds[0].tick) if len(worlds) > 1 else 1


def mirrored_points(worlds: list[World], cfg, team: str, goalkeepers: bool) -> tuple[np.ndarray, np.ndarray]:
    """Positions of `team`'s robots (or the ball for team ""), turned so that the team attacks +x."""
    half = cfg.half_ticks
    xs: list[float] = []
    ys: list[float] = []
    for w in worlds:
        a_dir = 1.0 if w.tick < half else -1.0
        if team == "":
            xs.append(a_dir * w.ball_x)
            ys.append(a_dir * w.ball_y)
            continue
        d = a_dir if team == "a" else -a_dir
        for r in w.robots:
            if r.team == team and (goalkeepers or r.robot != 0):
                xs.append(d * r.x)
                ys.append(d * r.y)
    return np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)


def heatmap(worlds: list[World], cfg, path: Path, draw_field, goalkeepers: bool = False) -> str:
    """heatmap.png: ball, team a, team b; each attacking towards +x; seconds per cell on a colour bar."""
    import matplotlib.pyplot as plt

    f = cfg.field
    extent = [[-f.length / 2 - f.runoff, f.length / 2 + f.runoff], [-f.width / 2 - f.runoff, f.width / 2 + f.runoff]]
    cell = 0.5  # [m]
    bins = [max(1, round((hi - lo) / cell)) for lo, hi in extent]
    period = cfg.timing.dt * _frame_ticks(worlds)  # [s] per frame
    who = "field players" if not goalkeepers else "all robots"
    panels = (("ball (team a's attacking direction)", ""), (f"team a, {who}", "a"), (f"team b, {who}", "b"))
    grids = [cell_seconds(worlds, cfg, team, goalkeepers, bins, extent, period) for _, team in panels]
    norm = shared_norm(grids)
    cmap = colour_map()
    fig, axes = plt.subplots(1, 3, figsize=(20, 5.4))
    for ax, (title, _), (seconds, xe, ye) in zip(axes, panels, grids):
        draw_field(ax, cfg)
        im = ax.imshow(
            seconds.T, origin="lower", extent=[xe[0], xe[-1], ye[0], ye[-1]], cmap=cmap, norm=norm, aspect="equal"
        )
        im.set_zorder(0.5)
        ax.set_title(title)
        ax.set_xlabel("x [m], attacking \u2192")
    fig.tight_layout(rect=(0, 0, 0.95, 1))
    bar = fig.colorbar(im, ax=list(axes), fraction=0.015, pad=0.01)
    bar.set_label(f"time in a {cell:g} m cell [s] (summed over robots)")
    fig.suptitle(
        f"where the play was: {cfg.home} (a) vs {cfg.away} (b), both halves, each team attacking to the right"
        + ("" if goalkeepers else "; goalkeepers left out (arena review --plots DIR --goalkeepers)")
    )
    return _save(fig, path)


def cell_seconds(worlds, cfg, team: str, goalkeepers: bool, bins, extent, period: float):
    """(seconds per cell, x edges, y edges) for one panel; NaN where nobody was."""
    xs, ys = mirrored_points(worlds, cfg, team, goalkeepers)
    ok = ~(np.isnan(xs) | np.isnan(ys))
    h, xe, ye = np.histogram2d(xs[ok], ys[ok], bins=bins, range=extent)
    return np.where(h > 0, h * period, np.nan), xe, ye


def shared_norm(grids):
    """One logarithmic scale from the least to the most time in any cell of any panel."""
    from matplotlib.colors import LogNorm

    values = np.concatenate([g[0][~np.isnan(g[0])] for g in grids] or [np.ones(1)])
    lo, hi = (float(values.min()), float(values.max())) if values.size else (1.0, 1.0)
    return LogNorm(vmin=lo, vmax=max(hi, lo * 10))


def colour_map():
    """HEAT_MAP with empty (NaN) cells fully transparent, so the field shows through."""
    from matplotlib import colormaps

    return colormaps[HEAT_MAP].with_extremes(bad=(0, 0, 0, 0))


def _save(fig, path: Path) -> str:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return str(path)
