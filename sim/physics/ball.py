"""Ball flight: height, bounces, kicks, lobs and placement.

* **Ball.** A dynamic circle. Rolling friction is a constant deceleration
  `rolling_decel`, realised as a pivot joint to the static body whose force is
  capped at mass * rolling_decel (Coulomb friction: it stops the ball exactly,
  without jitter). Restitution `restitution` against fence, posts, net and
  robots. While z >= robot height the ball flies over robots; while
  z >= goal height it also passes over posts and net (shape filters). A lob
  lands, bounces with the same restitution, and rolls on once the bounce is
  below `BOUNCE_STOP`. The height z is integrated here (ballistic,
  z'' = -9.81 m/s^2); the world is otherwise top-down 2D.
* **Kicker.** A kick fires once per `set_command` whose kick_speed > 0, as soon
  as the robot holds the ball or has it within reach in front: the ball leaves
  along the robot's heading at min(kick_speed, kick_max_speed). A lob splits
  that speed at `lob_angle` into horizontal and vertical launch speed.
  For `NO_CATCH_S` after its kick the kicker's dribbler cannot recapture the
  ball, so a soft pass with the dribbler still on leaves.
* **Placement.** `place_ball` puts the ball down (nobody holds it, line and
  no-progress events re-armed, the last toucher kept); `pin_ball` also keeps
  it on its restart spot until `start_play` (the referee puts it back if a
  robot moves it; nobody can capture or kick it).
"""

from __future__ import annotations

import math

import pymunk

from arena.sim.physics.bodies import (
    _CAT_BALL,
    _CAT_FENCE,
    _CAT_GOAL,
    _CAT_ROBOT,
    BOUNCE_STOP,
    GRAVITY,
    RobotBody,
)


class BallFlight:
    """Mixin of `Physics`: the ball's height and what launches or places it."""

    def _fly(self, s: list[float]) -> None:
        """One substep of the ball's height; shape filter by height; goal-line crossing height."""
        h = self._h
        self._vz -= GRAVITY * h
        self._z += self._vz * h
        if self._z <= 0.0 and self._vz < 0.0:
            self._z = 0.0
            self._vz = -self._ball_e * self._vz
            if self._vz < BOUNCE_STOP:
                self._vz = 0.0
                self._airborne = False
                if self._holder is None:
                    self._roll.max_force = self._roll_force
        self._set_ball_mask()
        ax = abs(s[self._ball_off])
        if ax < self._half_len:
            self._cross_high = False
        elif self._prev_ax < self._half_len:
            self._cross_high = self._z >= self._goal_height
        self._prev_ax = ax

    def _set_ball_mask(self) -> None:
        if self._dead:
            mask = 0
        else:
            mask = _CAT_FENCE
            if self._z < self._goal_height:
                mask |= _CAT_GOAL
            if self._z < self._robot_height:
                mask |= _CAT_ROBOT
        if mask != self._ball_mask:
            self._ball_mask = mask
            self._ball_shape.filter = pymunk.ShapeFilter(categories=_CAT_BALL, mask=mask)

    def _kick(self, r: RobotBody, s: list[float]) -> None:
        r.kick_armed = False
        r.catch_from = self.tick + self._no_catch_ticks
        self._release()
        cmd = r.cmd
        assert cmd is not None
        speed = min(cmd.kick_speed, self.cfg.robot.kick_max_speed)
        theta = s[r.off + 2]
        if cmd.kick_lob:
            flat = speed * math.cos(self.cfg.robot.lob_angle)
            self._vz = speed * math.sin(self.cfg.robot.lob_angle)
            self._z = 0.0
            self._airborne = True
            self._prev_ax = abs(s[self._ball_off])
            self._roll.max_force = 0.0
        else:
            flat = speed
        self._ball.velocity = flat * math.cos(theta), flat * math.sin(theta)
        self._dirty = True
        self._touch(r, s)

    def _stop_in_goal(self) -> None:
        self._release()
        self._ball.velocity = 0.0, 0.0
        self._z = self._vz = 0.0
        self._airborne = False
        self._dead = True
        self._set_ball_mask()
        self._dirty = True

    def place_ball(self, x: float, y: float, vx: float = 0.0, vy: float = 0.0) -> None:
        """Put the ball on the ground at (x, y) [m], rolling at (vx, vy) [m/s] (default: at rest).

        Nobody holds it afterwards, and the line and no-progress events are re-armed.
        """
        self._release()
        self._ball.position = x, y
        self._ball.velocity = vx, vy
        self._ball.angular_velocity = 0.0
        self._z = self._vz = 0.0
        self._airborne = False
        self._dead = False
        self._set_ball_mask()
        self._roll.max_force = self._roll_force
        self._out = abs(x) > self._half_len + self._ball_r or abs(y) > self._half_wid + self._ball_r
        self._cross_high = False
        self._idle_ticks = 0
        self._idle_fired = False
        self._anchor = (x, y)
        self._dirty = True

    def pin_ball(self, x: float, y: float) -> None:
        """Place the ball at rest on (x, y) [m] and keep it there until `start_play`."""
        self.place_ball(x, y)
        self._pin = (x, y)

    def teleport_ball(self, x: float, y: float, z: float, vx: float, vy: float, vz: float) -> None:
        """Scenario control (sim/director.py): the ball at (x, y, z) [m] moving at (vx, vy, vz) [m/s].

        Unlike `place_ball` it also releases a pinned set-piece ball; above the
        ground it flies from there.
        """
        self.place_ball(x, y, vx, vy)
        self._pin = None
        if z > 0.0 or vz > 0.0:
            self._z, self._vz = z, vz
            self._airborne = True
            self._prev_ax = abs(x)
            self._roll.max_force = 0.0
            self._set_ball_mask()
