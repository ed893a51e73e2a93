"""Angle wrapping and field/robot frame rotation shared by the navigation modules.

Conventions used by every module in :mod:`arena.navigation`:

* The **field frame** is the right-handed frame of the pitch: x, y in [m],
  angles in [rad] counter-clockwise from +x.
* The **robot frame** has its origin at the robot centre and +x along the
  robot heading ``theta``. Omni-wheel kinematics (paper 1 eq. 1-2, paper 2
  eq. 4) are written in the robot frame; navigators (APF, MAPF, SFM, F-SFM)
  return velocities in the field frame.
"""

from __future__ import annotations

import math

TAU = 2.0 * math.pi  # [rad]


def wrap_angle(angle: float) -> float:
    """Wrap ``angle`` [rad] to the half-open interval (-pi, pi]."""
    wrapped = math.remainder(angle, TAU)
    return math.pi if wrapped == -math.pi else wrapped


def field_to_robot(vx: float, vy: float, heading: float) -> tuple[float, float]:
    """Rotate a field-frame vector into the robot frame of a robot facing ``heading`` [rad]."""
    c, s = math.cos(heading), math.sin(heading)
    return c * vx + s * vy, -s * vx + c * vy


def robot_to_field(vx: float, vy: float, heading: float) -> tuple[float, float]:
    """Rotate a robot-frame vector into the field frame (inverse of :func:`field_to_robot`)."""
    c, s = math.cos(heading), math.sin(heading)
    return c * vx - s * vy, s * vx + c * vy
