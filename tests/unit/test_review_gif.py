"""The review GIF (tools/review/review.py `_animate`) shows the field: grass, robots, score and marks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from arena.recording.analysis.timeline import last_mark, score_at, timeline
from arena.runtime.config import MatchConfig
from arena.schemas.messages import RefCommand, Referee, RobotState, World
from arena.tools.review.review import _animate


def _match(cfg: MatchConfig, ticks: int = 60):
    worlds = [
        World(
            tick=k,
            t=k * cfg.timing.dt,
            ball_x=0.05 * k,
            ball_y=0.0,
            robots=[
                RobotState(team=t, robot=n, x=(-3 if t == "a" else 3) + n, y=n - 1.0, theta=0.0)
                for t in "ab"
                for n in range(3)
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


def test_the_gif_has_grass_robots_and_is_small(tmp_path: Path):
    cfg = MatchConfig(half_time=1.0)
    worlds, refs = _match(cfg)
    path = Path(_animate(worlds, cfg, tmp_path / "m.gif", refs))
    assert path.stat().st_size < 200_000
    with Image.open(path) as im:
        im.seek(im.n_frames // 2)
        px = np.asarray(im.convert("RGB")).reshape(-1, 3).astype(int)
    green = (px[:, 1] > px[:, 0] + 30) & (px[:, 1] > px[:, 2] + 30)
    assert green.mean() > 0.6, f"only {green.mean():.0%} of the frame is grass"
    cyan = (px[:, 2] > 200) & (px[:, 1] > 150) & (px[:, 0] < 80)
    magenta = (px[:, 0] > 200) & (px[:, 2] > 150) & (px[:, 1] < 80)
    assert cyan.sum() > 50 and magenta.sum() > 50, "robots of both teams are drawn"


def test_timeline_marks_and_score():
    cfg = MatchConfig(half_time=1.0)
    worlds, refs = _match(cfg)
    tl = timeline(worlds, refs, cfg.timing.dt, hz=10.0)
    assert len(tl["frames"]) == 12 and tl["robots"][0] == "a/0"
    assert score_at(tl, 10) == [0, 0] and score_at(tl, 40) == [1, 0]
    assert last_mark(tl, 35, within=50)["kind"] == "GOAL"
    assert last_mark(tl, 10, within=50)["kind"] == "KICKOFF"
    assert last_mark(tl, 200, within=50) is None
