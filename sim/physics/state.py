"""The engine's reads of the world: poses, velocities, the ball, and the G_V `World` message."""

from __future__ import annotations

import math

from arena.navigation.frames import TAU, wrap_angle
from arena.schemas.messages import RobotState, World


class State:
    """Mixin of `Physics`: reading the world back."""

    def robot_states(self) -> list[tuple[str, int, float, float, float, float, float, float]]:
        """Every robot's (team, n, x, y, theta, vx, vy, omega), field frame, in one pass.

        Built once per snapshot (the engine's senses, `world` and stuck check all read it): do not modify it.
        """
        s = self._fresh()
        if s is self._states_of:
            return self._states
        out, remainder, pi = [], math.remainder, math.pi
        for r in self._robots:
            o = r.off
            theta = remainder(s[o + 2], TAU)  # wrap_angle, inlined (the engine reads this every tick)
            out.append((r.team, r.n, s[o], s[o + 1], pi if theta == -pi else theta, s[o + 3], s[o + 4], s[o + 5]))
        self._states_of, self._states = s, out
        return out

    def commanded_speeds(self) -> list[float]:
        """[m/s] the linear speed each robot's command asks for (within the limits), 0 for a parked one,
        in `robot_states`' order (the stuck check's one call a period)."""
        out, hypot = [], math.hypot
        for r in self._robots:
            out.append(0.0 if r.parked else hypot(r.twist[0], r.twist[1]))
        return out

    def robot_pose(self, team: str, n: int) -> tuple[float, float, float]:
        """(x [m], y [m], theta [rad] in (-pi, pi]) in the field frame."""
        s, o = self._fresh(), self._by_id[(team, n)].off
        return s[o], s[o + 1], wrap_angle(s[o + 2])

    def robot_velocity(self, team: str, n: int) -> tuple[float, float, float]:
        """(vx [m/s], vy [m/s], omega [rad/s]) in the field frame."""
        s, o = self._fresh(), self._by_id[(team, n)].off
        return s[o + 3], s[o + 4], s[o + 5]

    def ball_state(self) -> tuple[float, float, float, float, float, float]:
        """(x, y, z [m], vx, vy, vz [m/s]) in the field frame."""
        s, b = self._fresh(), self._ball_off
        return s[b], s[b + 1], self._z, s[b + 3], s[b + 4], self._vz

    def holder(self) -> tuple[str, int] | None:
        """(team, n) of the robot whose dribbler holds the ball, else None."""
        h = self._holder
        return None if h is None else (h.team, h.n)

    def last_toucher(self) -> tuple[str, int] | None:
        """(team, n) of the last robot that touched, held or kicked the ball, else None."""
        last = self._last
        return None if last is None else (last.team, last.n)

    @property
    def robot_ids(self) -> list[tuple[str, int]]:
        """Every robot as (team, n): team a 0..N-1, then team b."""
        return [(r.team, r.n) for r in self._robots]

    @property
    def distance(self) -> dict[tuple[str, int], float]:
        """{(team, n): metres travelled so far (sum of per-substep displacements)}."""
        return {(r.team, r.n): r.dist for r in self._robots}

    def world(self, tick: int) -> World:
        """Ground truth as the G_V message."""
        states = self.robot_states()
        s, b, holder, last = self._snap, self._ball_off, self._holder, self._last
        # positional arguments in the fields' order (every tick; a keyword costs msgspec a name lookup)
        robots = []
        for r, (t, n, x, y, theta, vx, vy, w) in zip(self._robots, states):
            robots.append(RobotState(t, n, x, y, theta, vx, vy, w, r is holder))  # ..., omega, has_ball
        # tick, t, ball x y z vx vy vz, robots, last_team, last_robot
        return World(
            tick,
            tick * self._dt,
            s[b],
            s[b + 1],
            self._z,
            s[b + 3],
            s[b + 4],
            self._vz,
            robots,
            last.team if last else "",
            last.n if last else -1,
        )
