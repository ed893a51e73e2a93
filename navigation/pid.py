"""Discrete heading PID of paper 1 (Dewantara, Ariyadi and Oktavianto, "Responsive
Motion Control for Robot Soccer Navigation Using Adaptive Social Force Framework",
2021), eq. 15-16.

Eq. 15:  err(t) = beta(t) - theta(t),  wrapped to (-pi, pi]
Eq. 16:  V_theta(t) = k_p err(t) + k_i sum_{s<=t} err(s) + k_d (err(t) - err(t-1))

    beta     direction of the target seen from the robot, eq. 13 [rad]
    theta    robot heading [rad]
    V_theta  commanded angular velocity [rad/s]
    k_p, k_i, k_d  [1/s] each: they multiply an angle [rad] (the error, the sum of
             errors, the step-to-step change of error) to give [rad/s]. The paper's
             form has no sample time, so k_i and k_d hold for the paper's control
             step and must be retuned for another. Paper values (sec. 2.4):
             k_p = 20, k_i = 0.05, k_d = 50.

Angle wrapping: err is wrapped, and so is the difference err(t) - err(t-1),
so that a target crossing the +-pi seam gives no derivative kick. On the first
step there is no err(t-1) and the derivative term is 0. ``max_output`` (not in
the paper, infinite by default) clips V_theta; ``max_integral`` (likewise)
bounds the accumulated error as anti-windup.

With V_theta applied as a pure integrator, theta(t+1) = theta(t) + dt V_theta(t),
the loop is stable only for dt < 2 / (k_p + 2 k_d) (k_i neglected): 16.7 ms
with the paper's gains, so a slower control loop needs smaller gains.

The controller is a pure function of its state: :func:`step` returns the
command and a new :class:`PIDState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arena.navigation.frames import wrap_angle


@dataclass(frozen=True)
class PIDParams:
    k_p: float = 20.0  # [1/s] (paper 1 sec. 2.4)
    k_i: float = 0.05  # [1/s] on the sum of errors (paper 1 sec. 2.4)
    k_d: float = 50.0  # [1/s] on the step-to-step change of error (paper 1 sec. 2.4)
    max_output: float = math.inf  # [rad/s] |V_theta| clip (not in the paper)
    max_integral: float = math.inf  # [rad] |sum err| bound, anti-windup (not in the paper)


@dataclass(frozen=True)
class PIDState:
    integral: float = 0.0  # [rad] sum of wrapped errors so far
    prev_error: float | None = None  # [rad] err(t-1); None before the first step


def heading_error(beta: float, theta: float) -> float:
    """Eq. 15: err = beta - theta wrapped to (-pi, pi] [rad]."""
    return wrap_angle(beta - theta)


def step(state: PIDState, beta: float, theta: float, params: PIDParams = PIDParams()) -> tuple[float, PIDState]:
    """Eq. 16: (V_theta [rad/s], next state) for target direction ``beta`` and heading ``theta`` [rad]."""
    err = heading_error(beta, theta)
    integral = max(-params.max_integral, min(params.max_integral, state.integral + err))
    derivative = 0.0 if state.prev_error is None else wrap_angle(err - state.prev_error)
    out = params.k_p * err + params.k_i * integral + params.k_d * derivative
    out = max(-params.max_output, min(params.max_output, out))
    return out, PIDState(integral=integral, prev_error=err)
