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
* **diff**, a differential drive such as the E-puck: paper 3 eq. 13
  (`navigation/diffdrive.py`), two wheels on one axle, R = `wheel_radius`,
  axle length L = 2 `wheel_base` (`wheel_base` is wheel to robot centre, as
  for the omni models); forward kinematics is eq. 13's exact inverse. The
  wheels cannot move the body sideways: a body command's vy is dropped
  (which is what forward(inverse(twist)) gives).

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
from typing import TYPE_CHECKING

from arena.config import RobotParams
from arena.navigation.saturation import saturation_scale
from arena.schemas.messages import Cmd

if TYPE_CHECKING:
    from arena.navigation import diffdrive

Matrix = tuple[tuple[float, ...], ...]


def _rows(m) -> Matrix:
    return tuple(tuple(float(v) for v in row) for row in m)


def _diff_matrices(p: diffdrive.DiffDriveParams) -> tuple[Matrix, Matrix]:
    """Paper 3 eq. 13 as matrices: twist (vx, vy, omega) -> (phidot_r, phidot_l), and its inverse.

    Built column by column from `diffdrive.wheel_speeds` and `diffdrive.body_velocity`,
    so that the engine and the navigation library share one formula.
    """
    from arena.navigation import diffdrive

    (rv, lv), (rw, lw) = diffdrive.wheel_speeds(1.0, 0.0, p), diffdrive.wheel_speeds(0.0, 1.0, p)
    inv = ((rv, 0.0, rw), (lv, 0.0, lw))  # vy moves no wheel
    (vr, wr), (vl, wl) = diffdrive.body_velocity(1.0, 0.0, p), diffdrive.body_velocity(0.0, 1.0, p)
    fwd = ((vr, vl), (0.0, 0.0), (wr, wl))  # the wheels give no vy
    return inv, fwd


class Drive:
    """Wheel kinematics and limits of one robot model (`RobotParams.model`)."""

    def __init__(self, rp: RobotParams) -> None:
        # Only the model's own module is imported (each brings a frozen dataclass to build at import).
        if rp.model == "omni3":
            from arena.navigation import omni3

            p3 = omni3.Omni3Params(wheel_radius=rp.wheel_radius, wheel_distance=rp.wheel_base)
            inv, fwd = omni3.inverse_matrix(p3), omni3.forward_matrix(p3)
        elif rp.model == "omni4":
            from arena.navigation import omni4

            p4 = omni4.Omni4Params(wheel_distance=rp.wheel_base, wheel_radii=(rp.wheel_radius,) * 4)
            inv, fwd = omni4.inverse_matrix(p4), omni4.forward_matrix(p4)
        elif rp.model == "diff":
            from arena.navigation import diffdrive

            pd = diffdrive.DiffDriveParams(wheel_radius=rp.wheel_radius, axle_length=2.0 * rp.wheel_base)
            inv, fwd = _diff_matrices(pd)
        else:
            raise ValueError(f"unknown robot model {rp.model!r} (omni4, omni3 or diff)")
        self.holonomic = rp.model != "diff"  # False: the wheels give no sideways velocity
        self.inverse_rows: Matrix = _rows(inv)  # twist -> wheel speeds [rad/s]
        self.forward_rows: Matrix = _rows(fwd)  # wheel speeds -> twist
        self.wheels = len(self.inverse_rows)
        self.max_wheel_speed = rp.max_wheel_speed  # [rad/s]
        self.max_speed = rp.max_speed  # [m/s]
        self.max_omega = rp.max_omega  # [rad/s]
        # A capped body twist whose wheel speeds cannot reach the limit skips the per-wheel check
        # (`twist`): |a vx + b vy + c w| <= hypot(a, b) hypot(vx, vy) + |c| |w| (Cauchy-Schwarz), and
        # the 1e-9 margin is far above the rounding of either side, so the check would have passed.
        self._k_speed = max(math.hypot(a, b) for a, b, _ in self.inverse_rows)
        self._k_omega = max(abs(c) for _, _, c in self.inverse_rows)
        self._unsaturated = rp.max_wheel_speed * (1.0 - 1e-9) if rp.max_wheel_speed > 0.0 else -1.0

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
        # self._cap(cmd.vx, vy, cmd.omega), inlined (six times a tick); min(max(w, -m), m) as two tests
        vx, vy, w = cmd.vx, cmd.vy if self.holonomic else 0.0, cmd.omega
        speed, top, m = math.hypot(vx, vy), self.max_speed, self.max_omega
        if speed > top:
            vx, vy, speed = vx * top / speed, vy * top / speed, top
        if w < -m:
            w = -m
        elif w > m:
            w = m
        if speed * self._k_speed + abs(w) * self._k_omega <= self._unsaturated:
            return vx, vy, w  # within the wheels' limit, for sure (see __init__)
        # saturation_scale(self.wheel_speeds(vx, vy, w), ...) without building the
        # list: the engine does this six times a tick. Same operations, same bits
        # (and x * 1.0 == x, so an unsaturated twist is returned as it is).
        peak = 0.0
        for a, b, c in self.inverse_rows:
            m = abs(a * vx + b * vy + c * w)
            if m > peak:
                peak = m
        if 0.0 < self.max_wheel_speed and peak <= self.max_wheel_speed:
            return vx, vy, w
        s = saturation_scale((peak,), self.max_wheel_speed)  # raises for a limit <= 0
        return vx * s, vy * s, w * s
