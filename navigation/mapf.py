"""Modified artificial potential field (MAPF) of paper 3 (Puriyanto et al.,
"Webots-Based: Design of Collision Free Trajectory of Wheeled Mobile Robot Using
Artificial Potential Field"), eq. 4-7, after Sun, Tang and Lao (2017).

Eq. 2, attractive potential:  U_a(q) = 1/2 k_a D_rg^2           (as in :mod:`.apf`)
Eq. 4, repulsive potential:   U_r(q) = 1/2 k_r (1/D_or - 1/r)^2 D_rg^n   if D_or <= r, else 0
Eq. 5, total potential:       U_t(q) = U_a(q) + U_r(q)
Eq. 6-7, negative gradient, per axis (x shown; y is the same with y's):

    F_x = -k_a (x - x_g)
          - k_r (1/D_or - 1/r) (x_o - x) D_rg^n / D_or^3
          - 1/2 k_r n (1/D_or - 1/r)^2 (x - x_g) D_rg^(n-2)

The factor D_rg^n makes the repulsion vanish at the goal, so the goal stays the
global minimum when an obstacle lies within r of it (the paper's GNRON case,
"goal non-reachable due to obstacle nearby"). The third term pulls towards the
goal in proportion to the repulsive potential. In the paper's SAROG case
(robot, obstacle and goal on one line) the field on the line has no lateral
component, for APF and MAPF alike; what gets the robot round the obstacle is
the heading dynamics of the differential-drive controller (paper 3 eq. 9-11,
:func:`arena.navigation.diffdrive.track_direction`), see docs/navigation.md.

Symbols and units (F is used as a velocity field, as in :mod:`.apf`):

    q = (x, y) robot [m];  q_g = (x_g, y_g) goal [m];  q_o = (x_o, y_o) obstacle [m]
    D_rg  robot-goal distance [m];  D_or  obstacle-robot distance [m]
    r     safe distance [m]
    k_a   attractive gain [1/s]   (printed as k_alpha in eq. 6-7, a typo: k_alpha is the controller gain of eq. 11)
    k_r   repulsive gain [m^(4-n)/s]
    n     tuning exponent [-] (Table I: 1 for SAROG, 5 for GNRON)

Several obstacles add their repulsive terms (the paper has one).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from arena.navigation.base import EPS_DISTANCE, Vec2, clip_speed, points, xy


@dataclass(frozen=True)
class MAPFParams:
    k_a: float = 1.0  # [1/s] attractive gain (paper 3 Table I)
    k_r: float = 50.0  # [m^(4-n)/s] repulsive gain (paper 3 Table I)
    safe_distance: float = 0.3  # [m] r, obstacle influence radius, centre to centre (paper 3 sec. III-B)
    n: float = 1.0  # [-] exponent on D_rg (paper 3 Table I: 1 in environment 1, 5 in environment 2)
    max_speed: float = 2.0  # [m/s] speed clip (paper 1 Table 1, v0)


DEFAULT = MAPFParams()
# Paper 3 Table I.
ENVIRONMENT_1 = MAPFParams(n=1.0)  # SAROG
ENVIRONMENT_2 = MAPFParams(n=5.0)  # GNRON


def repulsive_potential(
    pos: Sequence[float], goal: Sequence[float], obstacle: Sequence[float], params: MAPFParams = DEFAULT
) -> float:
    """Eq. 4: U_r = 1/2 k_r (1/D_or - 1/r)^2 D_rg^n inside the safe distance, 0 outside."""
    d = math.hypot(obstacle[0] - pos[0], obstacle[1] - pos[1])
    if d > params.safe_distance:
        return 0.0
    if d < EPS_DISTANCE:
        return math.inf
    f = 1.0 / d - 1.0 / params.safe_distance
    d_rg = math.hypot(pos[0] - goal[0], pos[1] - goal[1])
    return 0.5 * params.k_r * f * f * d_rg**params.n


def potential(
    pos: Sequence[float], goal: Sequence[float], obstacles: Sequence[Sequence[float]], params: MAPFParams = DEFAULT
) -> float:
    """Eq. 5: U_t = U_a + sum_j U_r,j."""
    dx, dy = pos[0] - goal[0], pos[1] - goal[1]
    u_a = 0.5 * params.k_a * (dx * dx + dy * dy)  # eq. 2
    return u_a + sum(repulsive_potential(pos, goal, o, params) for o in points(obstacles))


def force(
    pos: Sequence[float], goal: Sequence[float], obstacles: Sequence[Sequence[float]], params: MAPFParams = DEFAULT
) -> Vec2:
    """Eq. 6-7: (F_x, F_y), the negative gradient of eq. 5 [m/s], not clipped.

    At the goal itself (D_rg < EPS_DISTANCE) the third term is taken as 0: its
    limit for n > 1, and its direction is undefined for n <= 1. An obstacle
    exactly at ``pos`` is skipped.
    """
    x, y = xy(pos)
    gx, gy = xy(goal)
    k_r, r, n = params.k_r, params.safe_distance, params.n
    inv_r = 1.0 / r
    ex, ey = x - gx, y - gy  # (q - q_g)
    fx = -params.k_a * ex
    fy = -params.k_a * ey
    d_rg = math.hypot(ex, ey)
    d_rg_n = d_rg**n
    d_rg_n2 = d_rg ** (n - 2.0) if d_rg >= EPS_DISTANCE else 0.0
    for ox, oy in points(obstacles):
        dx, dy = x - ox, y - oy  # -(q_o - q)
        d = math.hypot(dx, dy)
        if d > r or d < EPS_DISTANCE:
            continue
        f = 1.0 / d - inv_r
        c2 = k_r * f * d_rg_n / (d * d * d)  # second term, along (q - q_o)
        c3 = 0.5 * k_r * n * f * f * d_rg_n2  # third term, along -(q - q_g)
        fx += c2 * dx - c3 * ex
        fy += c2 * dy - c3 * ey
    return fx, fy


def step(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: MAPFParams = DEFAULT,
) -> Vec2:
    """Navigator contract (see :mod:`arena.navigation.base`): the MAPF force clipped to max_speed.

    ``vel`` is unused: MAPF is a static field.
    """
    fx, fy = force(pos, goal, obstacles, params)
    return clip_speed(fx, fy, params.max_speed)
