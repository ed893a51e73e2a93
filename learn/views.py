"""What a learning env shows besides its observations: the ground-truth state for centralised critics,
the rendered field, and the discrete form's action masks (docs/learning.md)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from arena.config import MatchConfig
from arena.learn.match import SteppedMatch
from arena.strategies.learned import DISCRETE

BALL_SPEED = 10.0  # [m/s] ball velocities are divided by this
ROBOT_PART = 8  # present, x, y, cos, sin, vx, vy, omega
HAS_BALL = 13  # the flat observation's index of has_ball (the `ball` part's last number)
KICK = next(i for i, (name, _) in enumerate(DISCRETE) if name == "kick")


def state_size(robots: int) -> int:
    return 6 + 2 * robots * ROBOT_PART + 3


def state_space(robots: int) -> spaces.Box:
    n = state_size(robots)
    return spaces.Box(np.full(n, -30.0, np.float32), np.full(n, 30.0, np.float32), dtype=np.float32)


def state(m: SteppedMatch | None, team: str) -> np.ndarray:
    """Ground truth (the latest `world`) in `team`'s attack frame: the ball (x / half length, y / half width,
    z [m], vx, vy, vz / 10 m/s); every robot of `team`, then of the other, by number (present, x / half
    length, y / half width, cos and sin of its heading, vx, vy / max_speed, omega / max_omega); then goals
    for, goals against, and the fraction of the match played. Zeros before the first `world`."""
    cfg = m.cfg if m is not None else MatchConfig()
    out = np.zeros(state_size(cfg.robots), np.float32)
    w = m.world() if m is not None else None
    if w is None:
        return out
    s = m.attack_dir_a if team == "a" else -m.attack_dir_a
    hl, hw = cfg.field.length / 2, cfg.field.width / 2
    r = cfg.robot
    v: list[float] = [s * w.ball_x / hl, s * w.ball_y / hw, w.ball_z]
    v += [s * w.ball_vx / BALL_SPEED, s * w.ball_vy / BALL_SPEED, w.ball_vz / BALL_SPEED]
    by = {(x.team, x.robot): x for x in w.robots}
    for t in (team, "b" if team == "a" else "a"):
        for n in range(cfg.robots):
            x = by.get((t, n))
            if x is None:
                v += [0.0] * ROBOT_PART
                continue
            v += [1.0, s * x.x / hl, s * x.y / hw, s * math.cos(x.theta), s * math.sin(x.theta)]
            v += [s * x.vx / r.max_speed, s * x.vy / r.max_speed, x.omega / r.max_omega]
    ours, theirs = m.score if team == "a" else m.score[::-1]
    v += [ours, theirs, min(1.0, m.tick / max(1, cfg.total_ticks))]
    out[:] = np.clip(np.array(v, np.float32), -30.0, 30.0)
    return out


def action_mask(flat_obs: np.ndarray) -> np.ndarray:
    """The discrete moves possible now (int8, 1 = possible): every move, but the kick only while the
    robot holds the ball (without it the kick is no kick)."""
    mask = np.ones(len(DISCRETE), np.int8)
    if flat_obs[HAS_BALL] < 0.5:
        mask[KICK] = 0
    return mask


class Renderer:
    """The field as match.gif draws it (review/animation.py), one RGB array per call."""

    def __init__(self):
        self._painter: Any = None
        self._cfg: MatchConfig | None = None

    def __call__(self, m: SteppedMatch | None) -> np.ndarray:
        from arena.recording.analysis.timeline import timeline
        from arena.review.animation import HEIGHT, WIDTH, Painter
        from arena.review.review import _draw_field as draw_field

        if m is None or m.world() is None:
            return np.zeros((HEIGHT, WIDTH, 3), np.uint8)
        if self._cfg is not m.cfg:
            self._painter = Painter(m.cfg, timeline([], [], m.cfg.timing.dt), draw_field)
            self._cfg = m.cfg
        ref = m.referee
        banner = None
        if ref is not None and ref.command != "START":
            banner = f"{ref.command.replace('_', ' ')} {ref.command_team}".strip()
        return np.asarray(self._painter.paint(m.world(), m.score, banner))
