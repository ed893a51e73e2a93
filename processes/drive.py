"""The engine's wheel model: a robot's `Cmd` to the body twist its wheels can give.

A robot commands either a body twist (`Cmd.mode == "body"`: vx, vy [m/s] in
the body frame and omega [rad/s]) or its wheel speeds (`mode == "wheels"`:
one angular speed [rad/s] per wheel). Both go through the same wheels:

* **omni4**, the IRIS robot: paper 2 eq. 3-4 (`navigation/omni4.py`), four
  wheels at 45, 135, 225 and 315 degrees, l = `wheel_base`,
  r = `wheel_radius`; forward kinematics is the least-squares pseudo-inverse.
* **omni3**, the Festo Robotino: paper 1 eq. 1-2 (`navigation/omni3.py`),
  three wheels at 180, 60 and -60 degrees, L = `wheel_base`,
  R = `wheel_radius`; forward kinematics is the exact inverse of eq. 2.

Wheel speeds are saturated at `max_wheel_speed` by scaling the whole wheel
vector (`navigation/saturation.py`), so the robot keeps its direction of
travel and only slows down. Then the controller's limits apply: the
translation is capped at `max_speed` (vector norm), the turn rate at
`max_omega`.

* wheels: twist = forward(saturate(w)), then capped;
* body: the twist is capped first, then scaled by the saturation factor of
  its own wheel speeds inverse(twist). Kinematics are linear and forward is a
  left inverse of inverse, so this equals forward(saturate(inverse(twist)))
  without the rounding of the round trip: a zero component stays exactly 0.

A wheel command with the wrong number of wheels for the model gives no motion
(the engine rejects such frames before they get here).
"""

from __future__ import annotations

import math

from arena.navigation import omni3, omni4
from arena.navigation.saturation import saturation_scale
from arena.runtime.config import RobotParams
from arena.schemas.messages import Cmd

Matrix = tuple[tuple[float, ...], ...]


def _rows(m) -> Matrix:
    return tuple(tuple(float(v) for v in row) for row in m)


class Drive:
    """Wheel kinematics and limits of one robot model (`RobotParams.model`)."""

    def __init__(self, rp: RobotParams) -> None:
        if rp.model == "omni3":
            p3 = omni3.Omni3Params(wheel_radius=rp.wheel_radius, wheel_distance=rp.wheel_base)
            inv, fwd = omni3.inverse_matrix(p3), omni3.forward_matrix(p3)
        elif rp.model == "omni4":
            p4 = omni4.Omni4Params(wheel_distance=rp.wheel_base, wheel_radii=(rp.wheel_radius,) * 4)
            inv, fwd = omni4.inverse_matrix(p4), omni4.forward_matrix(p4)
        else:
            raise ValueError(f"unknown robot model {rp.model!r} (omni4 or omni3)")
        self.inverse_rows: Matrix = _rows(inv)  # twist -> wheel speeds [rad/s]
        self.forward_rows: Matrix = _rows(fwd)  # wheel speeds -> twist
        self.wheels = len(self.inverse_rows)
        self.max_wheel_speed = rp.max_wheel_speed  # [rad/s]
        self.max_speed = rp.max_speed  # [m/s]
        self.max_omega = rp.max_omega  # [rad/s]

    def wheel_speeds(self, vx: float, vy: float, omega: float) -> list[float]:
        """Inverse kinematics: wheel angular speeds [rad/s] for a body twist, unsaturated."""
        return [a * vx + b * vy + c * omega for a, b, c in self.inverse_rows]

    def body_twist(self, wheels: list[float]) -> tuple[float, float, float]:
        """Forward kinematics: (vx [m/s], vy [m/s], omega [rad/s]) from wheel speeds [rad/s]."""
        vx, vy, w = (sum(m * s for m, s in zip(row, wheels)) for row in self.forward_rows)
        return vx, vy, w

    def _cap(self, vx: float, vy: float, omega: float) -> tuple[float, float, float]:
        speed = math.hypot(vx, vy)
        if speed > self.max_speed:
            vx, vy = vx * self.max_speed / speed, vy * self.max_speed / speed
        return vx, vy, min(max(omega, -self.max_omega), self.max_omega)

    def twist(self, cmd: Cmd) -> tuple[float, float, float]:
        """The body twist (vx, vy [m/s], omega [rad/s]) that `cmd` gives, within every limit."""
        if cmd.mode == "wheels":
            if len(cmd.wheels) != self.wheels:
                return 0.0, 0.0, 0.0
            s = saturation_scale(cmd.wheels, self.max_wheel_speed)
            return self._cap(*self.body_twist([w * s for w in cmd.wheels]))
        vx, vy, w = self._cap(cmd.vx, cmd.vy, cmd.omega)
        s = saturation_scale(self.wheel_speeds(vx, vy, w), self.max_wheel_speed)
        return vx * s, vy * s, w * s
