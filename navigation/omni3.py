"""Three-wheel omnidirectional drive (Festo Robotino) of paper 1 (Dewantara,
Ariyadi and Oktavianto, "Responsive Motion Control for Robot Soccer Navigation
Using Adaptive Social Force Framework", 2021), eq. 1-2.

Eq. 2, inverse kinematics, robot-frame twist -> wheel speeds:

    [w1]         [   0      -1   L ] [V_x    ]
    [w2] = 1/R * [ -sqrt3/2  1/2 L ] [V_y    ]
    [w3]         [  sqrt3/2  1/2 L ] [V_theta]

Row i is the general omni-wheel row [-sin a_i, cos a_i, L] / R (compare paper 2
eq. 4) with wheels at a = 180, 60 and -60 degrees from the robot's +x axis.

Eq. 1, forward kinematics, is computed as the (pseudo-)inverse of eq. 2. The
matrix printed as eq. 1 has rows 1 and 3 equal to that inverse, but its second
row [-R/3, -2R/3, 2R/3] is not: the inverse of eq. 2 has [-2R/3, R/3, R/3]
(a pure V_y = 1 gives w = (-1, 1/2, 1/2)/R, and the printed row maps it to
1/3). The printed row is taken as a typo.

Symbols and units: V_x, V_y robot-frame velocity [m/s] (+x forward);
V_theta yaw rate [rad/s]; w_i = v_x^i, wheel i's angular speed [rad/s]
(the paper's "motor speed"; gear ratio not included); R wheel radius [m];
L distance from the robot centre to each wheel [m].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

_S3 = math.sqrt(3.0) / 2.0


@dataclass(frozen=True)
class Omni3Params:
    wheel_radius: float = 0.04  # [m] R, Robotino wheel (80 mm diameter; not given in paper 1)
    wheel_distance: float = 0.135  # [m] L, centre to wheel, Robotino (not given in paper 1)


def inverse_matrix(params: Omni3Params = Omni3Params()) -> NDArray[np.float64]:
    """The 3x3 matrix of eq. 2 [rad/m, rad/m, rad]."""
    big_l = params.wheel_distance
    return (
        np.array(
            [[0.0, -1.0, big_l], [-_S3, 0.5, big_l], [_S3, 0.5, big_l]],
            dtype=np.float64,
        )
        / params.wheel_radius
    )


def forward_matrix(params: Omni3Params = Omni3Params()) -> NDArray[np.float64]:
    """Eq. 1 as the pseudo-inverse of eq. 2 (the exact inverse: eq. 2 is square and invertible)."""
    return np.linalg.pinv(inverse_matrix(params))


def inverse(vx: float, vy: float, omega: float, params: Omni3Params = Omni3Params()) -> NDArray[np.float64]:
    """Eq. 2: wheel angular speeds (w1, w2, w3) [rad/s] for a robot-frame twist ([m/s], [m/s], [rad/s])."""
    return inverse_matrix(params) @ np.array([vx, vy, omega], dtype=np.float64)


def forward(wheels: Sequence[float] | NDArray[np.float64], params: Omni3Params = Omni3Params()) -> NDArray[np.float64]:
    """Eq. 1 (corrected): robot-frame twist (V_x [m/s], V_y [m/s], V_theta [rad/s]) from wheel speeds [rad/s]."""
    return forward_matrix(params) @ np.asarray(wheels, dtype=np.float64)
