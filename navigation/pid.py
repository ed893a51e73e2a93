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

from arena.navigation.frames import TAU, wrap_angle


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


def update(
    integral: float, prev_error: float | None, beta: float, theta: float, params: PIDParams = PIDParams()
) -> tuple[float, float, float]:
    """Eq. 15-16 on plain floats: (V_theta [rad/s], next integral [rad], err [rad]) for the state
    (``integral``, ``prev_error``); :func:`step` without the state objects, for per-tick callers."""
    remainder, pi = math.remainder, math.pi
    err = remainder(beta - theta, TAU)  # eq. 15, wrap_angle inlined
    if err == -pi:
        err = pi
    bound = params.max_integral
    integral += err
    if not -bound < integral < bound:  # the clip, only where it can change the value (or on NaN)
        integral = max(-bound, min(bound, integral))
    if prev_error is None:
        derivative = 0.0
    else:
        derivative = remainder(err - prev_error, TAU)
        if derivative == -pi:
            derivative = pi
    out = params.k_p * err + params.k_i * integral + params.k_d * derivative
    bound = params.max_output
    if not -bound < out < bound:
        out = max(-bound, min(bound, out))
    return out, integral, err


def step(state: PIDState, beta: float, theta: float, params: PIDParams = PIDParams()) -> tuple[float, PIDState]:
    """Eq. 16: (V_theta [rad/s], next state) for target direction ``beta`` and heading ``theta`` [rad]."""
    out, integral, err = update(state.integral, state.prev_error, beta, theta, params)
    return out, PIDState(integral=integral, prev_error=err)
