"""Possession: the dribbler captures, holds and loses the ball.

* **Dribbler.** A robot whose dribbler is on captures the ball when it lies in
  front of its front face (within `DRIBBLE_REACH` of it, centred within
  `DRIBBLE_HALF_WIDTH`, low): the ball is pinned just in front of the face by
  a pivot joint and moves with the robot. The holder loses it when its turn
  rate exceeds dribble_max_omega, when the dribbler is switched off, or to a
  challenge: another robot's body touches the ball, or another robot with its
  own dribbler on comes within `CHALLENGE_DIST` of the ball. A robot that lost
  a challenge cannot recapture for `NO_CATCH_S`, nor challenge the new holder
  (by dribbler or body) for `NO_CHALLENGE_S`, so that two robots at one ball do
  not swap it every tick. One holder at a time.
"""

from __future__ import annotations

import math

import pymunk

from arena.sim.physics.bodies import (
    _ROBOT_TYPE0,
    CATCH_MAX_Z,
    DRIBBLE_HALF_WIDTH,
    DRIBBLE_REACH,
    DRIBBLE_SLACK,
    RobotBody,
)


class Possession:
    """Mixin of `Physics`: who holds the ball."""

    def _on_contact(self, arbiter: pymunk.Arbiter, space: pymunk.Space, i: int) -> None:
        arbiter.restitution = self._ball_e
        self._contacts.append(i)

    def _handle_contacts(self, s: list[float]) -> None:
        for i in self._contacts:
            r = self._robots[i]
            holder = self._holder
            if holder is not None and holder is not r:
                if self.tick >= r.challenge_from:
                    self._lose(holder)
            elif self._can_capture(r) and self._in_reach(r, s):
                self._capture(r, s)
            self._touch(r, s)
        self._contacts.clear()

    def _can_capture(self, r: RobotBody) -> bool:
        return (
            r.dribbler and self._holder is None and not self._dead and self._pin is None and self.tick >= r.catch_from
        )

    def _in_reach(self, r: RobotBody, s: list[float]) -> bool:
        if self._z > CATCH_MAX_Z:
            return False
        o, b = r.off, self._ball_off
        dx, dy = s[b] - s[o], s[b + 1] - s[o + 1]
        c, sn = math.cos(s[o + 2]), math.sin(s[o + 2])
        fx = c * dx + sn * dy
        fy = c * dy - sn * dx
        return self._face - DRIBBLE_SLACK <= fx <= self._face + DRIBBLE_REACH and abs(fy) <= DRIBBLE_HALF_WIDTH

    def _capture(self, r: RobotBody, s: list[float]) -> None:
        o = r.off
        theta, w = s[o + 2], s[o + 5]
        c, sn = math.cos(theta), math.sin(theta)
        d = self._hold_dist
        self._ball.position = s[o] + d * c, s[o + 1] + d * sn
        self._ball.velocity = s[o + 3] - w * d * sn, s[o + 4] + w * d * c
        self._z = self._vz = 0.0
        self._airborne = False
        self._set_ball_mask()
        self._roll.max_force = 0.0
        self._space.add(r.hold)
        self._holder = r
        r.carry_from = (s[o], s[o + 1])
        self._carry_fouled = False
        self._dirty = True
        self._touch(r, s)

    def _release(self) -> None:
        holder = self._holder
        if holder is None:
            return
        self._space.remove(holder.hold)
        self._holder = None
        if not self._airborne:
            self._roll.max_force = self._roll_force

    def _lose(self, holder: RobotBody) -> None:
        holder.catch_from = self.tick + self._no_catch_ticks
        holder.challenge_from = self.tick + self._no_challenge_ticks
        self._release()

    def _challenged(self, holder: RobotBody, s: list[float]) -> bool:
        """Another robot touches the held ball, or wants it (dribbler on) and is close."""
        bx, by, tick, reach = s[self._ball_off], s[self._ball_off + 1], self.tick, self._touch_reach
        near = False  # another robot's centre within `reach` of the ball's on both axes
        for r in self._robots:
            if r is holder:
                continue
            if (
                r.dribbler
                and tick >= r.challenge_from
                and math.hypot(s[r.off] - bx, s[r.off + 1] - by) < self._challenge
            ):
                return True
            near = near or (abs(s[r.off] - bx) <= reach and abs(s[r.off + 1] - by) <= reach)
        if not near:
            return False  # no footprint can touch the ball: the shape query (~8 k instructions) would find none
        for hit in self._space.shape_query(self._ball_shape):
            t = hit.shape.collision_type - _ROBOT_TYPE0
            if t >= 0 and hit.shape.body is not holder.body and tick >= self._robots[t].challenge_from:
                return True
        return False

    def _check_holder(self, holder: RobotBody, s: list[float]) -> None:
        """End of a tick: the holder turns too fast, is challenged, or has carried the ball too far."""
        if abs(s[holder.off + 5]) > self.cfg.robot.dribble_max_omega:
            self._release()
        elif self._challenged(holder, s):
            self._lose(holder)
        elif not self._carry_fouled and self._carried_too_far(holder, s):
            self._carry_fouled = True
            b = self._ball_off
            self._event("FOUL_DRIBBLING", holder.team, s[b], s[b + 1], robot=holder.n)

    def _carried_too_far(self, holder: RobotBody, s: list[float]) -> bool:
        x0, y0 = holder.carry_from
        return math.hypot(s[holder.off] - x0, s[holder.off + 1] - y0) > self._dribble_limit
