"""A robot's sensors: the paper's 360-degree LIDAR-like sensor plus odometry.

`sense()` turns the engine's ground truth into what robot n may know at a
tick (the G_R_n data pair), all in SI units:

* self pose [m, m, rad]: the true pose plus gaussian noise (pose_sigma on x
  and y, heading_sigma on theta), theta wrapped to (-pi, pi];
* odometry [m/s, rad/s]: the true velocity in the body frame (x forward,
  y left), without noise;
* the ball, if its centre lies within ball_range of the robot's centre: field
  frame position plus gaussian noise of sigma det_sigma + det_sigma_per_m *
  range on each axis; no occlusion;
* other robots (both teams, never itself) within robot_range: team colour and
  noisy field-frame position (same noise model), sorted by range, no number;
* has_ball: whether its dribbler holds the ball.

Every draw comes from the caller's `random.Random`, in a fixed order, so a
seeded generator reproduces the same readings.
"""

from __future__ import annotations

import math
import random

from arena.processes.physics import Physics, wrap_angle
from arena.runtime.config import SensorParams
from arena.schemas.messages import BallSeen, Pose, RobotSeen, Sense


def sense(physics: Physics, team: str, n: int, tick: int, rng: random.Random, p: SensorParams) -> Sense:
    """What robot (team, n) senses at `tick`; see the module docstring."""
    gauss = rng.gauss
    x, y, theta = physics.robot_pose(team, n)
    vx, vy, omega = physics.robot_velocity(team, n)
    c, s = math.cos(theta), math.sin(theta)
    pose = Pose(
        x=x + gauss(0.0, p.pose_sigma),
        y=y + gauss(0.0, p.pose_sigma),
        theta=wrap_angle(theta + gauss(0.0, p.heading_sigma)),
    )

    bx, by = physics.ball_state()[:2]
    rng_ball = math.hypot(bx - x, by - y)
    if rng_ball <= p.ball_range:
        sigma = p.det_sigma + p.det_sigma_per_m * rng_ball
        ball = BallSeen(visible=True, x=bx + gauss(0.0, sigma), y=by + gauss(0.0, sigma))
    else:
        ball = BallSeen()

    near = []
    for other in physics.robot_ids:
        if other[0] == team and other[1] == n:
            continue
        ox, oy, _ = physics.robot_pose(*other)
        d = math.hypot(ox - x, oy - y)
        if d <= p.robot_range:
            near.append((d, other[0], ox, oy))
    near.sort()
    robots = []
    for d, t, ox, oy in near:
        sigma = p.det_sigma + p.det_sigma_per_m * d
        robots.append(RobotSeen(team=t, x=ox + gauss(0.0, sigma), y=oy + gauss(0.0, sigma)))

    return Sense(
        tick=tick,
        pose=pose,
        vx=c * vx + s * vy,
        vy=c * vy - s * vx,
        omega=omega,
        ball=ball,
        robots=robots,
        has_ball=physics.holder() == (team, n),
    )
