"""The trajectory and heatmap pictures of `arena review --plots` (issue 19: plots a team can read).

* One colour per robot: the team's hue (MSL cyan for a, magenta for b), a
  darker shade for a lower number, so the goalkeeper is the darkest.
* Trajectories: one panel per half, since the teams change ends at half time;
  a placement (a jump between two frames: a restart, a robot parked off the
  field) breaks the line instead of drawing it across the field.
* Heatmaps: coordinates mirrored so that every panel's team attacks towards +x
  in both halves (the ball: team a's direction), a colour bar in seconds per
  cell, and the goalkeepers left out unless asked for (they stand in one cell
  for the whole match and drown everyone else).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from arena.recording.analysis.review import JUMP
from arena.schemas.messages import World

HUES = {"a": "Blues", "b": "RdPu"}  # matplotlib colour maps of the two teams' hues
BALL = "#ff8c00"


def robot_colour(team: str, number: int, robots: int):
    """The team's hue, darker for a lower number: goalkeeper (0) darkest, all clearly apart."""
    from matplotlib import colormaps

    shade = 0.95 - 0.55 * number / max(1, robots - 1)  # 0.95 .. 0.40 of the colour map
    return colormaps[HUES[team]](shade)


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
    """trajectories.png: first and second half side by side, one colour per robot."""
    import matplotlib.pyplot as plt

    half = cfg.half_ticks
    fig, axes = plt.subplots(1, 2, figsize=(18, 7.2))
    for ax, (title, lo, hi, a_dir) in zip(axes, (("first half", 0, half, 1), ("second half", half, 2 * half + 1, -1))):
        draw_field(ax, cfg)
        tracks, ball = split_tracks(worlds, lo, hi)
        for name, (xs, ys) in tracks.items():
            team, n = name.split("/")
            label = name + (" (GK)" if n == "0" else "")
            ax.plot(xs, ys, color=robot_colour(team, int(n), cfg.robots), lw=1.0, label=label)
        ax.plot(ball[0], ball[1], color=BALL, lw=0.8, ls=(0, (3, 1.5)), label="ball")
        right, left = "\u2192", "\u2190"
        a_arrow, b_arrow = (right, left) if a_dir > 0 else (left, right)
        ax.set_title(f"{title}: a attacks {a_arrow}, b attacks {b_arrow}")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=10, frameon=False)
    fig.suptitle(f"trajectories: {cfg.home} (a) vs {cfg.away} (b), seed {cfg.seed}")
    fig.tight_layout(rect=(0, 0.06, 1, 1))  # room for the legend below the panels
    return _save(fig, path)


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
    period = cfg.timing.dt * (worlds[1].tick - worlds[0].tick if len(worlds) > 1 else 1)  # [s] per frame
    who = "field players" if not goalkeepers else "all robots"
    fig, axes = plt.subplots(1, 3, figsize=(20, 5.4))
    for ax, (title, team) in zip(
        axes, (("ball (team a's attacking direction)", ""), (f"team a, {who}", "a"), (f"team b, {who}", "b"))
    ):
        xs, ys = mirrored_points(worlds, cfg, team, goalkeepers)
        ok = ~(np.isnan(xs) | np.isnan(ys))
        h, xe, ye = np.histogram2d(xs[ok], ys[ok], bins=bins, range=extent)
        seconds = np.where(h > 0, h * period, np.nan)  # empty cells show the field
        draw_field(ax, cfg)
        im = ax.imshow(
            seconds.T, origin="lower", extent=[xe[0], xe[-1], ye[0], ye[-1]], cmap="inferno", aspect="equal", zorder=0.5
        )
        bar = fig.colorbar(im, ax=ax, fraction=0.035, pad=0.02)
        bar.set_label(f"time in a {cell:g} m cell [s]")
        ax.set_title(title)
        ax.set_xlabel("x [m], attacking \u2192")
    fig.tight_layout()
    fig.suptitle(
        f"where the play was: {cfg.home} (a) vs {cfg.away} (b), both halves, each team attacking to the right"
        + ("" if goalkeepers else "; goalkeepers left out (arena review --plots DIR --goalkeepers)")
    )
    return _save(fig, path)


def _save(fig, path: Path) -> str:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return str(path)
