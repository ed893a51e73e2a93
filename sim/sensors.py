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

Noise comes from the caller's numpy `Generator`, one per robot. Every call
draws the same number of standard normals (3 + 2 + 2 per other robot, seen or
not), so a robot's noise stream never depends on what it happened to see, and
one vectorised draw replaces ~30 calls of `random.gauss` (the engine's hottest
Python code before). The engine wraps each generator in a `NormalStream`,
which draws a few thousand normals at a time: a numpy call per robot per tick
was half the cost of `sense`, and the numbers are the same (a Generator's
standard normals come out in the same order whatever the block size).
"""

from __future__ import annotations

import math

import numpy as np

from arena.config import SensorParams
from arena.navigation.frames import TAU
from arena.schemas.messages import BallSeen, Pose, RobotSeen, Sense
from arena.sim.physics import Physics

RobotStates = list[tuple[str, int, float, float, float, float, float, float]]


class NormalStream:
    """A numpy Generator's standard normals, drawn `block` at a time and handed out in order."""

    __slots__ = ("rng", "block", "_buf", "_i")

    def __init__(self, rng: np.random.Generator, block: int = 4096):
        self.rng = rng
        self.block = block
        self._buf: list[float] = []
        self._i = 0

    def take(self, n: int) -> list[float]:
        """The next n normals of the stream (exactly what `rng.standard_normal(n)` would give)."""
        i, j = self._i, self._i + n
        if j <= len(self._buf):
            self._i = j
            return self._buf[i:j]
        out = self._buf[i:]
        while len(out) < n:
            self._buf = self.rng.standard_normal(self.block).tolist()
            need = n - len(out)
            out += self._buf[:need]
            self._i = min(need, self.block)
        return out


def sense(
    physics: Physics,
    team: str,
    n: int,
    tick: int,
    rng: np.random.Generator | NormalStream,
    p: SensorParams,
    states: RobotStates | None = None,
) -> Sense:
    """What robot (team, n) senses at `tick`; see the module docstring.

    `states` is `physics.robot_states()`; pass it when sensing for several
    robots of a tick, so that the snapshot is read once (`sense_every` reads
    the ball and the holder once too).
    """
    if states is None:
        states = physics.robot_states()
    me = next((st for st in states if st[1] == n and st[0] == team), None)
    if me is None:
        raise ValueError(f"no robot {team}/{n} in the states")
    n_z = 3 + 2 * len(states)
    z = rng.take(n_z) if isinstance(rng, NormalStream) else rng.standard_normal(n_z).tolist()
    return _sense(states, [(me, z)], physics.ball_state(), physics.holder(), tick, p)[0]


def sense_every(
    physics: Physics, tick: int, robots: list[tuple[tuple[str, int], NormalStream]], p: SensorParams
) -> list[Sense]:
    """`sense()` of each (robot, its noise stream) of `robots`, in that order, the world read once."""
    states, index = physics.robot_states(), physics.robot_index
    n_z = 3 + 2 * len(states)
    picks = []
    for r, rng in robots:
        i, j = rng._i, rng._i + n_z  # NormalStream.take(n_z), its usual case inlined
        if j <= len(rng._buf):
            rng._i = j
            picks.append((states[index[r]], rng._buf[i:j]))
        else:
            picks.append((states[index[r]], rng.take(n_z)))
    return _sense(states, picks, physics.ball_state(), physics.holder(), tick, p)


def _sense(
    states: RobotStates,
    picks: list[tuple[tuple[str, int, float, float, float, float, float, float], list[float]]],
    ball_state: tuple[float, ...],
    holder: tuple[str, int] | None,
    tick: int,
    p: SensorParams,
) -> list[Sense]:
    """Each (robot `me` of `states`, its normals `z`: 3 + 2 per robot of `states`) of `picks` at `tick`.

    One loop over the robots rather than a call per robot: the engine senses six robots a tick.
    The messages are built with positional arguments in their fields' order (~40 a tick; a keyword
    costs msgspec a name lookup).
    """
    cos, sin, remainder, hypot, pi = math.cos, math.sin, math.remainder, math.hypot, math.pi
    heading_sigma, pose_sigma, det, per_m = p.heading_sigma, p.pose_sigma, p.det_sigma, p.det_sigma_per_m
    ball_range, robot_range = p.ball_range, p.robot_range
    bx, by = ball_state[0], ball_state[1]
    out = []
    for me, z in picks:
        team, n, x, y, theta, vx, vy, omega = me
        c, s = cos(theta), sin(theta)
        heading = remainder(theta + heading_sigma * z[2], TAU)  # wrap_angle, inlined
        pose = Pose(x + pose_sigma * z[0], y + pose_sigma * z[1], pi if heading == -pi else heading)  # x, y, theta
        d_ball = hypot(bx - x, by - y)
        if d_ball <= ball_range:
            sigma = det + per_m * d_ball
            ball = BallSeen(True, bx + sigma * z[3], by + sigma * z[4])  # visible, x, y
        else:
            ball = BallSeen()
        near = []
        i = 5
        for st in states:
            if st is me:
                continue
            ox, oy = st[2], st[3]
            d = hypot(ox - x, oy - y)
            if d <= robot_range:
                sigma = det + per_m * d
                near.append((d, st[0], ox + sigma * z[i], oy + sigma * z[i + 1]))
            i += 2
        near.sort()
        seen = []
        for _, t, nx, ny in near:
            seen.append(RobotSeen(t, nx, ny))  # team, x, y
        # tick, pose, vx, vy, omega, ball, robots, has_ball
        out.append(
            Sense(
                tick,
                pose,
                c * vx + s * vy,
                c * vy - s * vx,
                omega,
                ball,
                seen,
                holder is not None and holder[1] == n and holder[0] == team,
            )
        )
    return out
