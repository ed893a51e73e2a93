"""Artificial potential field (Khatib 1985) as written in paper 3 (Puriyanto et al.,
"Webots-Based: Design of Collision Free Trajectory of Wheeled Mobile Robot Using
Artificial Potential Field"), eq. 2-3, with the force as the negative gradient.

Eq. 2, attractive potential:  U_a(q) = 1/2 k_a D_rg^2
Eq. 3, repulsive potential:   U_r(q) = 1/2 k_r (1/D_or - 1/r)^2   if D_or <= r, else 0

Negative gradient (paper 3 eq. 6-7 with n = 0), summed over obstacles j:

    F(q) = -k_a (q - q_g) + sum_j k_r (1/D_j - 1/r) (q - q_oj) / D_j^3   [D_j <= r]

Symbols and units. The navigator treats F as a velocity field (gradient descent
on U), so U is in [m^2/s] and F in [m/s]:

    q = (x, y)  robot position [m];  q_g goal [m];  q_o obstacle centre [m]
    D_rg = ||q - q_g||  robot-goal distance [m]
    D_or = ||q_o - q||  obstacle-robot distance, centre to centre [m]
    r    safe distance: the influence radius of an obstacle [m]
    k_a  attractive gain [1/s]
    k_r  repulsive gain [m^4/s]

Paper 3 has one obstacle; several obstacles add their repulsive terms. The
result is clipped to ``max_speed`` without changing its direction (not in the
paper, which uses the force only for its direction, eq. 9).
Defaults are paper 3 Table I (environments 1 and 2); ``max_speed`` is paper 1
Table 1's v0 so that the navigators compare at the same top speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from arena.navigation.base import EPS_DISTANCE, Vec2, clip_speed, points, xy


@dataclass(frozen=True)
class APFParams:
    k_a: float = 1.0  # [1/s] attractive gain (paper 3 Table I)
    k_r: float = 50.0  # [m^4/s] repulsive gain (paper 3 Table I)
    safe_distance: float = 0.3  # [m] r, obstacle influence radius, centre to centre (paper 3 sec. III-B)
    max_speed: float = 2.0  # [m/s] speed clip (paper 1 Table 1, v0)


DEFAULT = APFParams()


def attractive_potential(pos: Sequence[float], goal: Sequence[float], params: APFParams = DEFAULT) -> float:
    """Eq. 2: U_a = 1/2 k_a D_rg^2 [m^2/s]."""
    dx, dy = pos[0] - goal[0], pos[1] - goal[1]
    return 0.5 * params.k_a * (dx * dx + dy * dy)


def repulsive_potential(pos: Sequence[float], obstacle: Sequence[float], params: APFParams = DEFAULT) -> float:
    """Eq. 3: U_r = 1/2 k_r (1/D_or - 1/r)^2 inside the safe distance, 0 outside [m^2/s]."""
    d = math.hypot(obstacle[0] - pos[0], obstacle[1] - pos[1])
    if d > params.safe_distance:
        return 0.0
    if d < EPS_DISTANCE:
        return math.inf
    f = 1.0 / d - 1.0 / params.safe_distance
    return 0.5 * params.k_r * f * f


def potential(
    pos: Sequence[float], goal: Sequence[float], obstacles: Sequence[Sequence[float]], params: APFParams = DEFAULT
) -> float:
    """Total potential U_a + sum_j U_r,j [m^2/s]."""
    return attractive_potential(pos, goal, params) + sum(repulsive_potential(pos, o, params) for o in points(obstacles))


def force(
    pos: Sequence[float], goal: Sequence[float], obstacles: Sequence[Sequence[float]], params: APFParams = DEFAULT
) -> Vec2:
    """Negative gradient of eq. 2 + eq. 3 at ``pos``: (F_x, F_y) [m/s], not clipped.

    An obstacle exactly at ``pos`` (closer than EPS_DISTANCE) gives no defined
    direction and is skipped.
    """
    x, y = xy(pos)
    gx, gy = xy(goal)
    k_r, r = params.k_r, params.safe_distance
    inv_r = 1.0 / r
    fx = -params.k_a * (x - gx)
    fy = -params.k_a * (y - gy)
    for ox, oy in points(obstacles):
        dx, dy = x - ox, y - oy
        d = math.hypot(dx, dy)
        if d > r or d < EPS_DISTANCE:
            continue
        c = k_r * (1.0 / d - inv_r) / (d * d * d)
        fx += c * dx
        fy += c * dy
    return fx, fy


def step(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: APFParams = DEFAULT,
) -> Vec2:
    """Navigator contract (see :mod:`arena.navigation.base`): the APF force clipped to max_speed.

    ``vel`` is unused: APF is a static field.
    """
    fx, fy = force(pos, goal, obstacles, params)
    return clip_speed(fx, fy, params.max_speed)
