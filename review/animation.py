"""match.gif of `arena review --plots`: the match as an animation a coach can follow.

One frame every FRAME_PERIOD seconds of play, FRAME_MS apart when played (5 x
real time), WIDTH pixels wide. Every robot has its colour and marker of
trajectories.png (review/plots.py) and its number; the ball is orange and larger
when in the air. A header gives the score and the clock, a banner the last goal
or restart, and a timeline strip under the field marks every goal and restart,
half time and now, with a legend.

matplotlib draws what does not move (the field, the strip and its legend) once;
Pillow draws the robots, ball and text onto a copy of it for every frame and
maps it onto one fixed palette. That keeps a 2 x 300 s match (1200 frames) at
a few milliseconds a frame instead of matplotlib's ~50 ms.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from arena.recording.analysis.timeline import last_mark, score_at, timeline
from arena.review.plots import BALL, robot_colour, robot_marker
from arena.schemas.messages import Referee, World

FRAME_PERIOD = 0.5  # [s] of play between two frames
FRAME_MS = 100  # [ms] between two frames when the GIF plays
WIDTH = 960  # [px]
HEIGHT = 780  # [px]
ROBOT_PX = 13  # [px] half the size of a robot's marker
GOAL, RESTART, HALF, NOW = "#ff1744", "#eeeeee", "#ffeb3b", "#00e5ff"  # the timeline strip's colours
SIDES = {"s": (4, 0), "^": (3, 0), "D": (4, 45), "v": (3, 180), "8": (8, 22.5)}  # marker: (sides, rotation [deg])


def frames_of(worlds: list[World], dt: float) -> list[World]:
    """One world every FRAME_PERIOD seconds of play (or every world, if they are further apart)."""
    if len(worlds) < 2:
        return list(worlds)
    per_world = (worlds[1].tick - worlds[0].tick) * dt  # [s]
    return worlds[:: max(1, round(FRAME_PERIOD / per_world))]


def animate(worlds: list[World], cfg, path: Path, refs: list[Referee], draw_field) -> str:
    """Write the GIF to `path`; `draw_field(ax, cfg, grass=False)` draws the lines and goals."""
    from PIL import Image, ImageDraw

    frames = frames_of(worlds, cfg.timing.dt)
    tl = timeline([], refs, cfg.timing.dt)  # marks and scores only
    background, to_px, strip = _background(cfg, tl, draw_field)
    fonts = _fonts()
    palette = _palette(background)
    images = []
    for w in frames:
        img = background.copy()
        draw = ImageDraw.Draw(img)
        for r in sorted(w.robots, key=lambda r: (r.team, r.robot)):
            _robot(draw, to_px(r.x, r.y), r.team, r.robot, fonts["number"])
        bx, by = to_px(w.ball_x, w.ball_y)
        rb = 6 * (1 + 2 * max(0.0, w.ball_z))  # [px] a lob looks larger
        draw.ellipse((bx - rb, by - rb, bx + rb, by + rb), fill=BALL, outline="black", width=1)
        a, b = score_at(tl, w.tick)
        head = f"{cfg.home} (a)  {a} : {b}  (b) {cfg.away}      {w.t:5.1f} s"
        draw.text((WIDTH / 2, 22), head, fill="white", font=fonts["head"], anchor="mm")
        m = last_mark(tl, w.tick, within=round(3.0 / cfg.timing.dt))
        if m is not None:
            banner = f"{m['kind'].replace('_', ' ')} {m['team']}".strip()
            draw.text(
                (WIDTH / 2, 80), banner, fill=HALF, font=fonts["mark"], anchor="mm", stroke_width=2, stroke_fill="black"
            )
        x0, x1, y0, y1 = strip
        cx = x0 + (x1 - x0) * min(1.0, w.tick / max(1, cfg.total_ticks))
        draw.line((cx, y0, cx, y1), fill=NOW, width=3)
        images.append(img.quantize(palette=palette, dither=Image.Dither.NONE))
    images[0].save(path, save_all=True, append_images=images[1:], duration=FRAME_MS, loop=0)
    return str(path)


def _robot(draw, xy: tuple[float, float], team: str, number: int, font) -> None:
    colour, marker = robot_colour(team, number), robot_marker(number)
    if marker == "o":
        x, y = xy
        draw.ellipse((x - ROBOT_PX, y - ROBOT_PX, x + ROBOT_PX, y + ROBOT_PX), fill=colour, outline="black", width=2)
    else:
        sides, rotation = SIDES[marker]
        r = ROBOT_PX * {3: 1.5, 4: 1.35, 8: 1.1}[sides]  # circumradius: about the circle's area
        draw.regular_polygon((xy, r), sides, rotation=rotation, fill=colour, outline="black", width=2)
    draw.text(xy, str(number), fill="white", font=font, anchor="mm", stroke_width=2, stroke_fill="black")


def _background(cfg, tl: dict, draw_field):
    """(the still image, metres -> pixels, the strip's pixel box (x0, x1, y0, y1))."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle
    from PIL import Image

    f = cfg.field
    fig = plt.figure(figsize=(WIDTH / 100, HEIGHT / 100), dpi=100, facecolor="#1b5e20")
    ax = fig.add_axes((0.01, 0.15, 0.98, 0.77))
    lo = (-f.length / 2 - f.runoff, -f.width / 2 - f.runoff)
    ax.add_patch(Rectangle(lo, f.length + 2 * f.runoff, f.width + 2 * f.runoff, fc="#2e7d32", ec="#9e9e9e", lw=2))
    draw_field(ax, cfg, grass=False)
    ax.set_axis_off()
    strip = fig.add_axes((0.05, 0.085, 0.9, 0.035), facecolor="#103d13")
    for m in tl["marks"]:
        goal = m["kind"] == "GOAL"
        strip.axvline(m["tick"], color=GOAL if goal else RESTART, lw=2.5 if goal else 0.8)
    strip.axvline(cfg.half_ticks, color=HALF, lw=1.5, ls=":")
    strip.set_xlim(0, max(1, cfg.total_ticks))
    strip.set_xticks([])
    strip.set_yticks([])
    legend = [
        Line2D([], [], color=GOAL, lw=2.5, label="goal"),
        Line2D([], [], color=RESTART, lw=1, label="restart (kickoff, free kick, throw-in, ...)"),
        Line2D([], [], color=HALF, lw=1.5, ls=":", label="half time"),
        Line2D([], [], color=NOW, lw=3, label="now"),
    ]
    fig.legend(handles=legend, loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=4, frameon=False, labelcolor="white")
    fig.canvas.draw()
    img = Image.fromarray(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
    (ax0, ay0), (ax1, ay1) = ax.transData.transform([(0.0, 0.0), (1.0, 1.0)])
    (sx0, sy0), (sx1, sy1) = strip.transAxes.transform([(0.0, 0.0), (1.0, 1.0)])
    plt.close(fig)
    h = img.height

    def to_px(x: float, y: float) -> tuple[float, float]:
        return ax0 + (ax1 - ax0) * x, h - (ay0 + (ay1 - ay0) * y)

    return img, to_px, (sx0, sx1, h - sy1, h - sy0)


def _palette(background):
    """One palette for every frame: the background's colours and every colour drawn on it."""
    from PIL import Image

    swatches = [robot_colour(t, n) for t in "ab" for n in range(6)] + [BALL, "black", "white", NOW, HALF]
    src = Image.new("RGB", (background.width, background.height + 20 * len(swatches)))
    src.paste(background)
    for i, colour in enumerate(swatches):
        src.paste(colour, (0, background.height + 20 * i, src.width, background.height + 20 * (i + 1)))
    return src.quantize(colors=256, method=Image.Quantize.MEDIANCUT)


def _fonts() -> dict:
    from matplotlib import font_manager
    from PIL import ImageFont

    bold = font_manager.findfont(font_manager.FontProperties(family="DejaVu Sans", weight="bold"))
    return {name: ImageFont.truetype(bold, size) for name, size in (("head", 20), ("mark", 34), ("number", 13))}
