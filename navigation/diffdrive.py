"""Differential-drive kinematics and the potential-field tracking law of paper 3
(Puriyanto et al., "Webots-Based: Design of Collision Free Trajectory of Wheeled
Mobile Robot Using Artificial Potential Field"), eq. 8, 9, 11 and 13.

Eq. 8, unicycle model (integrated here with forward Euler over ``dt``):

    xdot = v cos(theta),  ydot = v sin(theta),  thetadot = omega

Eq. 9, polar errors, with the field direction replacing the goal bearing:

    rho   = ||q_g - q||
    alpha = atan2(F_y, F_x) - theta
    beta  = -theta - alpha

Eq. 11, linear control law (its second line is printed "alpha = ..."; it is omega):

    v = k_rho rho,   omega = k_alpha alpha + k_beta beta

Eq. 13, wheel speeds. The paper prints v_r = v + omega L / (2R), v_l = v - omega L / (2R)
with L the E-puck "radius" and R the "ICC", which does not balance in units
(omega L / R is in [1/s], v in [m/s]). This module uses the dimensionally
consistent reading it was presumably taken from,

    phidot_r = (v + omega L / 2) / R,   phidot_l = (v - omega L / 2) / R

with L the axle length (distance between the wheels) [m] and R the wheel
radius [m], giving wheel angular speeds [rad/s]. :func:`body_velocity` is its
exact inverse.

Symbols and units: x, y [m]; theta, alpha, beta [rad]; v [m/s]; omega [rad/s];
rho [m]; k_rho, k_alpha, k_beta [1/s]; F_x, F_y any consistent unit (only the
direction is used).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arena.navigation.frames import wrap_angle


@dataclass(frozen=True)
class DiffDriveParams:
    wheel_radius: float = 0.0205  # [m] R, E-puck wheel radius (paper 3's robot)
    axle_length: float = 0.052  # [m] L, distance between the two wheels (E-puck)


@dataclass(frozen=True)
class PolarGains:
    """Eq. 11 gains; paper 3 Table I. Stable for k_rho > 0, k_beta < 0, k_alpha - k_beta > 0 (eq. 12)."""

    k_rho: float = 1.0  # [1/s]
    k_alpha: float = 5.0  # [1/s]
    k_beta: float = -1.0  # [1/s]


def unicycle_step(x: float, y: float, theta: float, v: float, omega: float, dt: float) -> tuple[float, float, float]:
    """Eq. 8 integrated with forward Euler over ``dt`` [s]; returns (x [m], y [m], theta [rad] wrapped)."""
    return x + v * math.cos(theta) * dt, y + v * math.sin(theta) * dt, wrap_angle(theta + omega * dt)


def wheel_speeds(v: float, omega: float, params: DiffDriveParams = DiffDriveParams()) -> tuple[float, float]:
    """Eq. 13 (dimensionally consistent reading): (phidot_r, phidot_l) [rad/s] for (v [m/s], omega [rad/s])."""
    half = 0.5 * omega * params.axle_length
    return (v + half) / params.wheel_radius, (v - half) / params.wheel_radius


def body_velocity(phidot_r: float, phidot_l: float, params: DiffDriveParams = DiffDriveParams()) -> tuple[float, float]:
    """Inverse of :func:`wheel_speeds`: (v [m/s], omega [rad/s]) from wheel angular speeds [rad/s]."""
    vr, vl = phidot_r * params.wheel_radius, phidot_l * params.wheel_radius
    return 0.5 * (vr + vl), (vr - vl) / params.axle_length


def track_direction(
    theta: float, fx: float, fy: float, rho: float, gains: PolarGains = PolarGains()
) -> tuple[float, float]:
    """Eq. 9 and 11: (v [m/s], omega [rad/s]) steering heading ``theta`` [rad] along the field (fx, fy).

    ``rho`` [m] is the distance to the goal. The paper gives the law for a
    target in front of the robot only; it is applied as written for every
    alpha (the robot always drives forward and turns towards the field).
    """
    alpha = wrap_angle(math.atan2(fy, fx) - theta)
    beta = wrap_angle(-theta - alpha)
    return gains.k_rho * rho, gains.k_alpha * alpha + gains.k_beta * beta
