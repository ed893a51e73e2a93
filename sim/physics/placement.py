"""Robot placement: put a robot somewhere, park a dead one beyond the fence, the kick-off positions."""

from __future__ import annotations

import math

import pymunk

from arena.config import TEAMS
from arena.sim.physics.bodies import FENCE_RADIUS

PARK_GAP = 1.0  # [m] a parked robot's centre beyond the fence


class Placement:
    """Mixin of `Physics`: where the referee and the engine put the robots."""

    def place_robot(self, team: str, n: int, x: float, y: float, theta: float) -> None:
        """Put robot n at rest on (x, y) [m] facing theta [rad]; it drops a held ball. A parked robot stays parked."""
        r = self._by_id[(team, n)]
        if r.parked:
            return
        self._put(r, x, y, theta)

    def teleport_robot(
        self, team: str, n: int, pose: tuple[float, float, float], twist: tuple[float, float, float]
    ) -> None:
        """Scenario control: robot n at `pose` (x, y [m], theta [rad]) moving at `twist` (field frame,
        [m/s], [rad/s]); its drive takes over from the next tick. A parked robot stays parked."""
        r = self._by_id[(team, n)]
        if r.parked:
            return
        self._put(r, *pose)
        r.body.velocity = twist[0], twist[1]
        r.body.angular_velocity = twist[2]

    def push_robot(self, team: str, n: int, vx: float, vy: float) -> None:
        """Scenario control: robot n moving at (vx, vy) [m/s] from where it stands, the ball it holds kept;
        its drive pulls it back to its command from there."""
        r = self._by_id[(team, n)]
        if not r.parked:
            r.body.velocity = vx, vy
            self._dirty = True

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
