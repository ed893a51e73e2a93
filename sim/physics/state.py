"""The engine's reads and writes of the world: robot placement, poses, the G_V `World` message."""

from __future__ import annotations

import math

import pymunk

from arena.navigation.frames import wrap_angle
from arena.runtime.config import TEAMS
from arena.schemas.messages import RobotState, World
from arena.sim.physics.bodies import FENCE_RADIUS

PARK_GAP = 1.0  # [m] a parked robot's centre beyond the fence


class State:
    """Mixin of `Physics`: placing robots and reading the world back."""

    def place_robot(self, team: str, n: int, x: float, y: float, theta: float) -> None:
        """Put robot n at rest on (x, y) [m] facing theta [rad]; it drops a held ball. A parked robot stays parked."""
        r = self._by_id[(team, n)]
        if r.parked:
            return
        self._put(r, x, y, theta)

    def park_robot(self, team: str, n: int) -> tuple[float, float]:
        """Take robot n off the field for good (its process died); returns where it stands [m].

        It drops a held ball and stands still beyond the fence, behind its
        team's end of the x axis, in a slot of its own. It collides with
        nothing (an empty shape filter: the ball, robots, fence and goals pass
        through it, and it could not reach them anyway), its commands are
        ignored, and set pieces never place it again.
        """
        r = self._by_id[(team, n)]
        f, size = self.cfg.field, self.cfg.robot.size
        x = (f.length / 2 + f.runoff + FENCE_RADIUS + PARK_GAP) * (-1 if team == "a" else 1)
        y = -f.width / 2 + n * 2 * size
        if not r.parked:
            r.cmd = None
            r.twist = (0.0, 0.0, 0.0)
            r.kick_armed = r.dribbler = False
            self._put(r, x, y, 0.0)
            for shape in r.body.shapes:
                shape.filter = pymunk.ShapeFilter(categories=0, mask=0)
            r.parked = True
        return x, y

    def parked(self) -> list[tuple[str, int]]:
        return [(r.team, r.n) for r in self._robots if r.parked]

    def _put(self, r, x: float, y: float, theta: float) -> None:
        if self._holder is r:
            self._release()
        r.body.position = x, y
        r.body.angle = theta
        r.body.velocity = 0.0, 0.0
        r.body.angular_velocity = 0.0
        r.ctrl.velocity = 0.0, 0.0
        r.ctrl.angular_velocity = 0.0
        r.ctrl_set = (0.0, 0.0, 0.0)
        self._space.reindex_shapes_for_body(r.body)
        self._dirty = True

    def kickoff_positions(self, kicking_team: str) -> None:
        """Ball on the centre spot; every robot in its own half, facing the opponent goal.

        Goalkeepers stand on their goal line's centre (just inside the field);
        the kicking team's robot 1 stands 0.5 m behind the ball; everybody else
        takes a fixed slot of its own half outside the centre circle.
        """
        f, size = self.cfg.field, self.cfg.robot.size
        half, hw = f.length / 2, f.width / 2
        slots = [  # (depth from the halfway line, y) [m], for robots 1..5
            (f.center_circle_radius + size, 0.0),
            (0.45 * half, 0.5 * hw),
            (0.45 * half, -0.5 * hw),
            (0.7 * half, 0.25 * hw),
            (0.7 * half, -0.25 * hw),
        ]
        self.place_ball(0.0, 0.0)
        for team in TEAMS:
            attack = self.attack_dir_a if team == "a" else -self.attack_dir_a
            theta = 0.0 if attack > 0 else math.pi
            for n in range(self.cfg.robots):
                if self._by_id[(team, n)].parked:
                    continue
                if n == 0:
                    depth, y = half - size / 2, 0.0
                elif n == 1 and team == kicking_team:
                    depth, y = 0.5, 0.0
                else:
                    depth, y = slots[n - 1]
                self.place_robot(team, n, -attack * depth, y, theta)

    def robot_states(self) -> list[tuple[str, int, float, float, float, float, float, float]]:
        """Every robot's (team, n, x, y, theta, vx, vy, omega), field frame, in one pass."""
        s = self._fresh()
        return [
            (r.team, r.n, s[r.off], s[r.off + 1], wrap_angle(s[r.off + 2]), s[r.off + 3], s[r.off + 4], s[r.off + 5])
            for r in self._robots
        ]

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
        s, b, holder, last = self._fresh(), self._ball_off, self._holder, self._last
        robots = [
            RobotState(
                team=r.team,
                robot=r.n,
                x=s[r.off],
                y=s[r.off + 1],
                theta=wrap_angle(s[r.off + 2]),
                vx=s[r.off + 3],
                vy=s[r.off + 4],
                omega=s[r.off + 5],
                has_ball=r is holder,
            )
            for r in self._robots
        ]
        return World(
            tick=tick,
            t=tick * self._dt,
            ball_x=s[b],
            ball_y=s[b + 1],
            ball_z=self._z,
            ball_vx=s[b + 3],
            ball_vy=s[b + 4],
            ball_vz=self._vz,
            robots=robots,
            last_team=last.team if last else "",
            last_robot=last.n if last else -1,
        )
