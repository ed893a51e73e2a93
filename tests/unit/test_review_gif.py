"""The review GIF (review/animation.py): grass, every robot in its own colour, a frame per half second of play."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from arena.config import MatchConfig
from arena.recording.analysis.timeline import last_mark, score_at, timeline
from arena.review import animation
from arena.review.plots import robot_colour
from arena.review.review import _draw_field
from arena.schemas.messages import RefCommand, Referee, RobotState, World


def _match(cfg: MatchConfig, ticks: int = 60, robots: int = 3):
    worlds = [
        World(
            tick=k,
            t=k * cfg.timing.dt,
            ball_x=0.05 * k,
            ball_y=0.0,
            robots=[
                RobotState(team=t, robot=n, x=(-5 if t == "a" else 1) + 0.8 * n, y=n - 1.0, theta=0.0)
                for t in "ab"
                for n in range(robots)
            ],
        )
        for k in range(ticks)
    ]
    refs = [
        Referee(tick=0, stage="FIRST_HALF", command="KICKOFF", commands=[RefCommand(name="KICKOFF", team="a")]),
        Referee(
            tick=30,
            stage="FIRST_HALF",
            command="GOAL",
            score_a=1,
            commands=[RefCommand(name="GOAL", team="a", tick=30)],
        ),
    ]
    return worlds, refs


def _pixels(path: Path, frame: int) -> np.ndarray:
    with Image.open(path) as im:
        im.seek(frame)
        return np.asarray(im.convert("RGB")).reshape(-1, 3).astype(int)


def test_the_gif_is_wide_with_grass_and_every_robot_in_its_own_colour(tmp_path: Path):
    cfg = MatchConfig(half_time=1.0)
    worlds, refs = _match(cfg, robots=6)
    path = Path(animation.animate(worlds, cfg, tmp_path / "m.gif", refs, _draw_field))
    with Image.open(path) as im:
        assert im.width >= 800, im.size
    px = _pixels(path, 1)
    green = (px[:, 1] > px[:, 0] + 30) & (px[:, 1] > px[:, 2] + 30)
    assert green.mean() > 0.6, f"only {green.mean():.0%} of the frame is grass"
    for team in "ab":
        for n in range(6):
            rgb = np.array([int(robot_colour(team, n)[i : i + 2], 16) for i in (1, 3, 5)])
            close = (np.abs(px - rgb).sum(axis=1) < 24).sum()
            assert close > 100, f"robot {team}/{n}'s colour {robot_colour(team, n)} covers only {close} px"


def test_a_frame_every_half_second_of_play_in_a_long_match(tmp_path: Path):
    cfg = MatchConfig(half_time=300.0)
    worlds, _ = _match(cfg, ticks=cfg.total_ticks + 1)
    worlds = worlds[::5]  # the recorder's 10 Hz
    frames = animation.frames_of(worlds, cfg.timing.dt)
    assert len(frames) == 1201 and frames[1].t - frames[0].t == animation.FRAME_PERIOD <= 1.0
    short = MatchConfig(half_time=2.0)
    worlds, refs = _match(short, ticks=short.total_ticks + 1)
    path = Path(animation.animate(worlds, short, tmp_path / "m.gif", refs, _draw_field))
    with Image.open(path) as im:
        assert im.n_frames == 9, "4 s of play at 2 frames a second, and the last"
        assert im.info["duration"] == animation.FRAME_MS


def test_the_timeline_strip_has_a_legend_and_marks_goals(tmp_path: Path):
    cfg = MatchConfig(half_time=1.0)
    worlds, refs = _match(cfg)
    background, _, (x0, x1, y0, y1) = animation._background(cfg, timeline([], refs, cfg.timing.dt), _draw_field)
    px = np.asarray(background)
    strip = px[round(y0) + 2 : round(y1) - 2, round(x0) : round(x1)]
    red = (strip[..., 0] > 200) & (strip[..., 1] < 60)
    assert red.any(), "the goal is marked red on the strip"
    below = px[round(y1) + 4 :, :]
    white_text = (below.min(axis=2) > 200).sum()
    assert white_text > 200, "a legend under the strip names goal, restart, half time and now"


def test_timeline_marks_and_score():
    cfg = MatchConfig(half_time=1.0)
    worlds, refs = _match(cfg)
    tl = timeline(worlds, refs, cfg.timing.dt, hz=10.0)
    assert len(tl["frames"]) == 12 and tl["robots"][0] == "a/0"
    assert score_at(tl, 10) == [0, 0] and score_at(tl, 40) == [1, 0]
    assert last_mark(tl, 35, within=50)["kind"] == "GOAL"
    assert last_mark(tl, 10, within=50)["kind"] == "KICKOFF"
    assert last_mark(tl, 200, within=50) is None


def test_the_half_time_frame_shows_the_kickoff_positions_under_its_banner():
    """The world of the half-time tick still has the first half's positions, and the referee's
    KICKOFF b of that tick made the GIF say "KICKOFF b" over them; the placement is one tick later."""
    cfg = MatchConfig(half_time=2.0)
    worlds, _ = _match(cfg, ticks=cfg.total_ticks + 1)
    frames = animation.frames_of(worlds, cfg.timing.dt, cfg.half_ticks)
    ticks = [w.tick for w in frames]
    assert cfg.half_ticks not in ticks and cfg.half_ticks + 1 in ticks, ticks
    assert ticks == sorted(ticks) and len(ticks) == 9
