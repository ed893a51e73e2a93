"""Four-wheel omnidirectional drive (IRIS robot) of paper 2 (the IRIS team's
"Advance Attack and Defense Strategy Algorithm with Dynamic Role Assignment for
Wheeled Soccer Robot"), eq. 3-4.

Eq. 4, wheel linear speeds from the robot-frame twist:

    v_i = -sin(a_i) xdot + cos(a_i) ydot + l thetadot,   i = 1..4

Eq. 3, wheel angular speeds:  phidot_i = v_i / r_i

Forward kinematics (not in the paper) is the least-squares inverse through the
pseudo-inverse of the 4x3 matrix diag(1/r_i) J: with four wheels the system is
over-determined, and wheel speeds that do not come from a rigid twist (slip)
are projected onto the nearest one.

Symbols and units: xdot, ydot robot-frame velocity [m/s] (+x forward);
thetadot yaw rate [rad/s]; a_i angle from the robot's x axis to wheel i's
axis, i.e. to the wheel's position seen from the centre [rad]; l distance from
the centre to the wheels [m]; r_i wheel radius [m]; v_i [m/s]; phidot_i [rad/s].

The paper gives neither the wheel angles nor l nor r_i. Defaults: wheels at
45, 135, 225 and 315 degrees (the usual X layout), l = 0.20 m for a 45 cm
square robot, r_i = 0.05 m. Setting a = (180, 60, -60) degrees, l = L and a
common r = R reproduces paper 1 eq. 2 for the three-wheel Robotino.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class Omni4Params:
    wheel_angles: tuple[float, ...] = tuple(math.radians(a) for a in (45.0, 135.0, 225.0, 315.0))  # [rad] a_i
    wheel_distance: float = 0.20  # [m] l, centre to wheel (assumed; not in paper 2)
    wheel_radii: tuple[float, ...] = (0.05, 0.05, 0.05, 0.05)  # [m] r_i (assumed; not in paper 2)

    def __post_init__(self) -> None:
        if len(self.wheel_angles) != len(self.wheel_radii):
            raise ValueError("need one radius per wheel angle")


def jacobian(params: Omni4Params = Omni4Params()) -> NDArray[np.float64]:
    """The matrix of eq. 4, rows [-sin a_i, cos a_i, l]: twist -> wheel linear speeds [m/s]."""
    return np.array([[-math.sin(a), math.cos(a), params.wheel_distance] for a in params.wheel_angles], dtype=np.float64)


def inverse_matrix(params: Omni4Params = Omni4Params()) -> NDArray[np.float64]:
    """Eq. 3 composed with eq. 4: twist -> wheel angular speeds [rad/s]."""
    return jacobian(params) / np.asarray(params.wheel_radii, dtype=np.float64)[:, None]


def forward_matrix(params: Omni4Params = Omni4Params()) -> NDArray[np.float64]:
    """Pseudo-inverse of :func:`inverse_matrix`: wheel angular speeds -> least-squares twist."""
    return np.linalg.pinv(inverse_matrix(params))


def wheel_linear_speeds(vx: float, vy: float, omega: float, params: Omni4Params = Omni4Params()) -> NDArray[np.float64]:
    """Eq. 4: v_i [m/s] for a robot-frame twist ([m/s], [m/s], [rad/s])."""
    return jacobian(params) @ np.array([vx, vy, omega], dtype=np.float64)


def inverse(vx: float, vy: float, omega: float, params: Omni4Params = Omni4Params()) -> NDArray[np.float64]:
    """Eq. 3-4: wheel angular speeds phidot_i [rad/s] for a robot-frame twist."""
    return inverse_matrix(params) @ np.array([vx, vy, omega], dtype=np.float64)


def forward(wheels: Sequence[float] | NDArray[np.float64], params: Omni4Params = Omni4Params()) -> NDArray[np.float64]:
    """Least-squares twist (xdot [m/s], ydot [m/s], thetadot [rad/s]) from wheel angular speeds [rad/s]."""
    return forward_matrix(params) @ np.asarray(wheels, dtype=np.float64)
