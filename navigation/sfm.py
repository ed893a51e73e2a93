"""Social force model (Helbing and Molnar 1995) as used for robot soccer in paper 1
(Dewantara, Ariyadi and Oktavianto, "Responsive Motion Control for Robot Soccer
Navigation Using Adaptive Social Force Framework", 2021), eq. 3-7 and 17-20,
with the parameters of its Table 1.

Eq. 3, navigation force:   F^n = F^g + sum_j F^o_j
Eq. 4, goal force:         F^g = m (v0 e_g - v) / tau
Eq. 5, obstacle force:     F^o_j = f^o_s + f^o_p
Eq. 6, social force:       f^o_s = k exp((r_ij - d_ij) / sigma) e_ij
Eq. 7, physical force:     f^o_p = k g(r_ij - d_ij) e_ij,   g(x) = max(x, 0)
Eq. 17, speed:             v_t = |F^n| t / m,  with t = tau
Eq. 18, direction:         alpha = atan2 of F^n (the paper writes it as the polar
                           sum of F^g along beta and F^o along gamma)
Eq. 19-20:                 V_x = v_t cos(alpha),  V_y = v_t sin(alpha)

Symbols and units:

    F^n, F^g, F^o   navigation, goal and obstacle forces [N]
    m        robot mass [kg]                           (Table 1: 20 kg)
    tau      relaxation ("updating") time [s]          (Table 1: 0.1 s)
    v0       desired = maximum speed [m/s]             (Table 1: 2 m/s)
    e_g      unit vector from the robot to the goal [-] (direction beta, eq. 13)
    v        robot's current velocity [m/s]
    k        obstacle gain: [N] in eq. 6, [N/m] in eq. 7 (the paper uses one number
             for both; Table 3 schemes #1 and #2: 100 and 300)
    r_ij     sum of robot radius r_i and obstacle radius r_j [m]
             (Table 1: proxemic radius 0.5 m, see SFMParams)
    d_ij     robot-obstacle centre distance [m] (eq. 12)
    sigma    effective range of the social force [m]   (Table 1: 0.5 m)
    e_ij     unit vector from obstacle j to the robot [-]; the obstacle's bearing
             gamma (eq. 14) points the other way, so e_ij = -(cos gamma, sin gamma)

Choices where the text is loose, all recorded in docs/navigation.md:

* Eq. 4 is printed as m d (v0 - v_t) / tau; it is implemented in Helbing's
  vector form m (v0 e_g - v) / tau.
* Eq. 7 is the contact ("physical") force: it acts only while the discs
  overlap (Helbing's g). Read literally it would pull the robot towards every
  obstacle farther than r_ij.
* Eq. 17 read literally makes the commanded speed the *change* of velocity
  over tau, so a robot already at v0 e_g would be told to stop. By default
  (``integrate=True``) the force is integrated over tau from the current
  velocity, v_cmd = v + F^n tau / m, which equals eq. 17 from rest and reduces
  to v0 e_g + sum_j F^o_j tau / m. ``integrate=False`` gives eq. 17 literally.
* The command is clipped to v0, the robot's maximum speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from arena.navigation.base import EPS_DISTANCE, Vec2, clip_speed, points, xy


@dataclass(frozen=True)
class SFMParams:
    mass: float = 20.0  # [kg] m (paper 1 Table 1)
    tau: float = 0.1  # [s] relaxation / updating time (Table 1)
    max_speed: float = 2.0  # [m/s] v0, desired and maximum speed (Table 1)
    robot_radius: float = 0.5  # [m] r_i, the robot's proxemic radius (Table 1)
    obstacle_radius: float = 0.0  # [m] r_j; 0 makes r_ij the Table 1 proxemic radius
    sigma: float = 0.5  # [m] effective range (Table 1)
    k: float = 100.0  # [N] and [N/m] obstacle gain (Table 3 scheme #1; #2 is 300)
    cutoff_distance: float = math.inf  # [m] obstacles farther than this are ignored (not in the paper)
    integrate: bool = True  # True: v + F^n tau / m; False: eq. 17 literally, F^n tau / m

    @property
    def r_ij(self) -> float:
        """Sum of robot and obstacle radii [m]."""
        return self.robot_radius + self.obstacle_radius


DEFAULT = SFMParams()
SCHEME_1 = SFMParams(k=100.0)  # paper 1 Table 3
SCHEME_2 = SFMParams(k=300.0)


def goal_force(pos: Sequence[float], vel: Sequence[float], goal: Sequence[float], params: SFMParams = DEFAULT) -> Vec2:
    """Eq. 4: F^g = m (v0 e_g - v) / tau [N]; e_g = 0 at the goal itself."""
    ex, ey = goal[0] - pos[0], goal[1] - pos[1]
    dg = math.hypot(ex, ey)
    if dg < EPS_DISTANCE:
        ex = ey = 0.0
    else:
        ex, ey = ex / dg, ey / dg
    c = params.mass / params.tau
    return c * (params.max_speed * ex - vel[0]), c * (params.max_speed * ey - vel[1])


def obstacle_force_magnitude(d: float, k: float, params: SFMParams = DEFAULT) -> float:
    """|F^o| = |f^o_s + f^o_p| (eq. 5-7) [N] at centre distance ``d`` [m] with gain ``k``; both act along e_ij."""
    overlap = params.r_ij - d
    return k * (math.exp(overlap / params.sigma) + (overlap if overlap > 0.0 else 0.0))


def obstacle_force(pos: Sequence[float], obstacle: Sequence[float], k: float, params: SFMParams = DEFAULT) -> Vec2:
    """Eq. 5-7: F^o_j [N] on the robot at ``pos`` from the obstacle centre ``obstacle`` with gain ``k``."""
    dx, dy = pos[0] - obstacle[0], pos[1] - obstacle[1]
    d = math.hypot(dx, dy)
    if d < EPS_DISTANCE or d > params.cutoff_distance:
        return 0.0, 0.0
    c = obstacle_force_magnitude(d, k, params) / d
    return c * dx, c * dy


def navigation_force(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: SFMParams = DEFAULT,
) -> Vec2:
    """Eq. 3 with the fixed gain ``params.k``: F^n [N]."""
    x, y = xy(pos)
    fx, fy = goal_force((x, y), vel, goal, params)
    r_ij, sigma, k, cutoff = params.r_ij, params.sigma, params.k, params.cutoff_distance
    exp = math.exp
    for ox, oy in points(obstacles):
        dx, dy = x - ox, y - oy
        d = math.hypot(dx, dy)
        if d < EPS_DISTANCE or d > cutoff:
            continue
        overlap = r_ij - d
        c = k * (exp(overlap / sigma) + (overlap if overlap > 0.0 else 0.0)) / d
        fx += c * dx
        fy += c * dy
    return fx, fy


def command_velocity(vel: Sequence[float], force: Sequence[float], params: SFMParams = DEFAULT) -> Vec2:
    """Eq. 17-20: the commanded field-frame velocity (V_x, V_y) [m/s] for navigation force ``force`` [N].

    v_t = |F^n| tau / m and alpha = direction of F^n (eq. 17-18), added to the
    current velocity when ``params.integrate`` (see the module docstring),
    then clipped to v0.
    """
    s = params.tau / params.mass
    vx, vy = force[0] * s, force[1] * s
    if params.integrate:
        vx += vel[0]
        vy += vel[1]
    return clip_speed(vx, vy, params.max_speed)


def step(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: SFMParams = DEFAULT,
) -> Vec2:
    """Navigator contract (see :mod:`arena.navigation.base`): SFM with the fixed gain ``params.k``."""
    v = xy(vel)
    return command_velocity(v, navigation_force(pos, v, goal, obstacles, params), params)
