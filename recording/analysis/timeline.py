"""A match as a compact timeline, for the review's animations (GIF, HTML replay).

From the `world` and `referee` streams of a recording:

* `frames`: the ground truth decimated to `hz` (10 Hz by default) and quantised:
  positions in centimetres and headings in centiradians, as integers, so a
  2 x 300 s match is 6000 frames of a few dozen small numbers;
* `marks`: goals and restarts (kickoffs, free kicks, throw-ins, corners, goal
  kicks, penalties, drop balls), at the tick the referee issued them;
* `scores`: the score after every change, with its time.

Everything is a pure function of the recording.
"""

from __future__ import annotations

import bisect
import math

from arena.schemas.messages import Referee, World
from arena.schemas.vocabulary import SET_PIECES

CM = 100.0  # [1/m] positions are stored in centimetres
CRAD = 100.0  # [1/rad] headings in centiradians


def timeline(worlds: list[World], refs: list[Referee], dt: float, hz: float = 10.0) -> dict:
    step = max(1, round(1.0 / (hz * dt)))
    robots = sorted({(r.team, r.robot) for w in worlds for r in w.robots})
    index = {r: i for i, r in enumerate(robots)}
    frames = []
    next_tick = None
    for w in worlds:
        if next_tick is not None and w.tick < next_tick:
            continue
        next_tick = w.tick + step
        pose = [None] * len(robots)
        for r in w.robots:
            pose[index[(r.team, r.robot)]] = [round(r.x * CM), round(r.y * CM), round(r.theta * CRAD)]
        ball = [round(w.ball_x * CM), round(w.ball_y * CM), round(max(0.0, w.ball_z) * CM)]
        frames.append({"tick": w.tick, "ball": ball, "robots": pose})
    marks, scores = [], [{"tick": 0, "score": [0, 0]}]
    for ref in refs:
        for c in ref.commands:
            if c.name == "GOAL":
                marks.append({"tick": c.tick, "kind": "GOAL", "team": c.team, "score": [ref.score_a, ref.score_b]})
            elif c.name in SET_PIECES:
                marks.append({"tick": c.tick, "kind": c.name, "team": c.team})
        if [ref.score_a, ref.score_b] != scores[-1]["score"]:
            scores.append({"tick": ref.tick, "score": [ref.score_a, ref.score_b]})
    return {
        "dt": dt,
        "robots": [f"{t}/{n}" for t, n in robots],
        "frames": frames,
        "marks": marks,
        "scores": scores,
    }


def score_at(tl: dict, tick: int) -> list[int]:
    """The score in force at `tick`."""
    ticks = [s["tick"] for s in tl["scores"]]
    return tl["scores"][max(0, bisect.bisect_right(ticks, tick) - 1)]["score"]


def last_mark(tl: dict, tick: int, within: int) -> dict | None:
    """The newest mark at or before `tick` at most `within` ticks old; a goal wins over the restarts after it."""
    recent = [m for m in tl["marks"] if tick - within <= m["tick"] <= tick]
    goals = [m for m in recent if m["kind"] == "GOAL"]
    return (goals or recent or [None])[-1]


def unquantise(v: int) -> float:
    return v / CM


def heading(v: int) -> float:
    return math.remainder(v / CRAD, 2 * math.pi)
