"""The ranges of a scenario's numbers: finite, inside the fence, within the model's limits.

A number outside them would reach the physics (a NaN or 1e308 position, a ball
beyond the fence that no rule can call) or run for ever (a time limit of
1e308 s); each check raises `ValueError` naming the key and the range."""

from __future__ import annotations

import math

from arena.config import MatchConfig

MAX_TIME_LIMIT = 3600.0  # [s] simulated, one run; a match is 2 x 300 s
MAX_BALL_SPEED = 20.0  # [m/s] horizontal, a teleported ball; the kicker's flat kick is 8 m/s
MAX_BALL_VZ = 20.0  # [m/s]
MAX_BALL_Z = 10.0  # [m]
MAX_REGION = 100.0  # [m] any corner of a region, from the centre spot
MAX_SCORE = 999
MAX_RULE = 1e6  # any `play.rules` value


def finite(v: float, where: str, lo: float, hi: float, unit: str = "") -> None:
    if not (math.isfinite(v) and lo <= v <= hi):
        raise ValueError(f"{where}: a number in [{lo:g}, {hi:g}]{unit}, got {v}")


def fence(cfg: MatchConfig, margin: float) -> tuple[float, float]:
    """The largest |x| and |y| [m] of a body's centre `margin` inside the fence."""
    f = cfg.field
    return f.length / 2 + f.runoff - margin, f.width / 2 + f.runoff - margin


def check_position(x, y, cfg: MatchConfig, margin: float, where: str) -> None:
    hx, hy = fence(cfg, margin)
    if x is not None:
        finite(x, f"{where}.x", -hx, hx, " m (inside the fence)")
    if y is not None:
        finite(y, f"{where}.y", -hy, hy, " m (inside the fence)")


def check_ball(b, cfg: MatchConfig, where: str) -> None:
    check_position(b.x, b.y, cfg, cfg.ball.radius, where)
    finite(b.z, f"{where}.z", 0.0, MAX_BALL_Z, " m")
    for key in ("vx", "vy"):
        v = getattr(b, key)
        if v is not None:
            finite(v, f"{where}.{key}", -MAX_BALL_SPEED, MAX_BALL_SPEED, " m/s")
    finite(b.vz, f"{where}.vz", -MAX_BALL_VZ, MAX_BALL_VZ, " m/s")
    speed = math.hypot(b.vx or 0.0, b.vy or 0.0)
    if speed > MAX_BALL_SPEED:
        raise ValueError(f"{where}: speed {speed:.3g} m/s, at most {MAX_BALL_SPEED:g} m/s")


def check_robot(r, cfg: MatchConfig, where: str) -> None:
    rp = cfg.robot
    check_position(r.x, r.y, cfg, rp.size / 2, where)
    if r.theta is not None:
        finite(r.theta, f"{where}.theta", -2 * math.pi, 2 * math.pi, " rad")
    for key in ("vx", "vy"):
        v = getattr(r, key)
        if v is not None:
            finite(v, f"{where}.{key}", -rp.max_speed, rp.max_speed, " m/s (the robot's max_speed)")
    speed = math.hypot(r.vx or 0.0, r.vy or 0.0)
    if speed > rp.max_speed + 1e-9:
        raise ValueError(f"{where}: speed {speed:.3g} m/s, more than the robot's max_speed {rp.max_speed:g} m/s")
    if r.omega is not None:
        finite(r.omega, f"{where}.omega", -rp.max_omega, rp.max_omega, " rad/s (the robot's max_omega)")


def check_spot(x, y, cfg: MatchConfig, where: str) -> None:
    """A referee's ball spot: on the field, lines included."""
    f = cfg.field
    if x is not None:
        finite(x, f"{where}.x", -f.length / 2, f.length / 2, " m (on the field)")
    if y is not None:
        finite(y, f"{where}.y", -f.width / 2, f.width / 2, " m (on the field)")


def check_control(c, cfg: MatchConfig, time_limit: float, where: str) -> None:
    rp = cfg.robot
    finite(c.seconds, f"{where}.seconds", cfg.timing.dt, time_limit, " s")
    finite(c.vx, f"{where}.vx", -rp.max_speed, rp.max_speed, " m/s (the robot's max_speed)")
    finite(c.vy, f"{where}.vy", -rp.max_speed, rp.max_speed, " m/s (the robot's max_speed)")
    finite(c.omega, f"{where}.omega", -rp.max_omega, rp.max_omega, " rad/s (the robot's max_omega)")
    finite(c.kick_speed, f"{where}.kick_speed", 0.0, rp.kick_max_speed, " m/s (the robot's kick_max_speed)")


def check_region(values: list[float], where: str) -> None:
    if len(values) != 4:
        raise ValueError(f"{where}: [x0, y0, x1, y1] in metres, got {values}")
    for v in values:
        finite(v, where, -MAX_REGION, MAX_REGION, " m")
    x0, y0, x1, y1 = values
    if x0 > x1 or y0 > y1:
        raise ValueError(f"{where}: [x0, y0, x1, y1] with x0 <= x1 and y0 <= y1 (corners low then high), got {values}")
