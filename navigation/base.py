"""The navigator contract shared by APF, MAPF, SFM and F-SFM, and its input helpers.

A navigator is a pure function::

    step(pos, vel, goal, obstacles, params) -> (vx, vy)

* ``pos``, ``vel``, ``goal``: 2-sequences (tuple, list or numpy array) in the
  field frame: position [m], current velocity [m/s], goal position [m].
* ``obstacles``: a sequence of (x, y) obstacle centres [m] in the field frame
  (a list of pairs or an ``(M, 2)`` numpy array, M >= 0). Obstacle size is a
  parameter of the navigator (all robots on a pitch are the same size).
* ``params``: the navigator's own frozen params dataclass; every ``step`` has a
  default taken from its paper.
* returns the desired velocity ``(vx, vy)`` [m/s] in the field frame as two
  Python floats, with ``hypot(vx, vy) <= params.max_speed``.

It mutates nothing, keeps no state between calls and reads no clock, so the
same inputs always give the same output. Heading is not part of the contract:
an omni robot turns with :mod:`arena.navigation.pid` (paper 1 eq. 15-16), a
differential-drive robot with :func:`arena.navigation.diffdrive.track_direction`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Protocol

Vec2 = tuple[float, float]

# Below this distance [m] a direction is undefined; the term that needs it is dropped.
EPS_DISTANCE = 1e-9  # [m]


class Navigator(Protocol):
    """``step(pos, vel, goal, obstacles, params) -> (vx, vy)``; see the module docstring."""

    def __call__(
        self,
        pos: Sequence[float],
        vel: Sequence[float],
        goal: Sequence[float],
        obstacles: Sequence[Sequence[float]],
        params: Any = ...,
    ) -> Vec2: ...


def xy(p: Sequence[float]) -> Vec2:
    """A 2-sequence (or numpy array) as a pair of Python floats."""
    return float(p[0]), float(p[1])


def points(obstacles: Sequence[Sequence[float]]) -> list[Vec2]:
    """Obstacle centres as a list of float pairs (numpy arrays go through ``tolist``, which is fast)."""
    tolist = getattr(obstacles, "tolist", None)
    rows = tolist() if tolist is not None else obstacles
    return [(float(o[0]), float(o[1])) for o in rows]


def clip_speed(vx: float, vy: float, max_speed: float) -> Vec2:
    """Scale ``(vx, vy)`` [m/s] down to ``max_speed`` [m/s] if faster, keeping its direction."""
    speed = math.hypot(vx, vy)
    if speed > max_speed:
        s = max_speed / speed
        return vx * s, vy * s
    return vx, vy
