"""Line and foul events, and play on or off.

* **Play and stoppages.** The engine switches play off (`stop_play`) when
  the referee stops the game and on again at START (`start_play`). While
  play is off nothing counts as a touch, no event is reported and the
  no-progress clock stands still. A new Physics is in play, unpinned.
* **Events.** `step()` returns the ball events of a tick, stamped with the
  new tick:
  TOUCH when the last toucher (contact, capture or kick) changes, and for
  the first touch after `start_play` (the set piece is taken);
  GOAL when the ball is wholly past a goal line between the posts and crossed
  the line below the crossbar (team: the side attacking that goal, from
  `attack_dir_a`), after which the ball rests in the net until placed;
  GOAL_LINE and TOUCH_LINE when it is wholly over a goal line (elsewhere, or
  over the crossbar) or a touch line: once per crossing, re-armed when the
  ball's centre is back inside the lines or the ball is placed; GOAL_LINE's
  team is the team defending that goal line, so that the referee can tell a
  goal kick from a corner by the last toucher;
  NO_PROGRESS once the ball, in play, has stayed within
  `RulesParams.progress_radius` of one point for `no_progress_s` (default
  `RulesParams.no_progress_s`): idle, or stuck between robots; re-armed when
  it gets out of that circle (which then moves to it) or is placed. Every
  event carries the ball position and the last toucher. Placing the ball
  keeps the last toucher.
* **Fouls** (reported as events with the offender's team and robot):
  FOUL_PUSHING when two robots of different teams start touching with a
  closing speed above `RulesParams.push_speed` (the normal component of the
  relative velocity at impact); the offender is the one that drove more
  into the other (the larger velocity component towards it), x/y the
  contact point. FOUL_DRIBBLING once per possession when the holder's centre
  gets farther than `RulesParams.dribble_limit` (MSL 3 m, straight line)
  from where it was when its dribbler took the ball; x/y the ball.
"""

from __future__ import annotations

import math

import pymunk

from arena.schemas.messages import BallEvent
from arena.schemas.vocabulary import other_team
from arena.sim.physics.bodies import _ROBOT_TYPE0, RobotBody


class Events:
    """Mixin of `Physics`: what the engine reports to the referee."""

    def _on_impact(self, arbiter: pymunk.Arbiter, space: pymunk.Space, pair: tuple[int, int]) -> None:
        """Robots of different teams start touching: pushing if they close fast enough."""
        a, b = arbiter.shapes
        i, j = pair if a.collision_type == _ROBOT_TYPE0 + pair[0] else pair[::-1]
        nx, ny = arbiter.normal  # from shape a to shape b
        va, vb = a.body.velocity, b.body.velocity
        into_b = va.x * nx + va.y * ny  # [m/s] a's speed towards b
        into_a = -(vb.x * nx + vb.y * ny)
        if into_b + into_a > self._push_speed:
            points = arbiter.contact_point_set.points
            px, py = points[0].point_a if points else a.body.position
            self._impacts.append((i if into_b >= into_a else j, px, py))

    def _handle_impacts(self) -> None:
        for offender, x, y in self._impacts:
            r = self._robots[offender]
            self._event("FOUL_PUSHING", r.team, x, y, robot=r.n)
        self._impacts.clear()

    def _touch(self, r: RobotBody, s: list[float]) -> None:
        if not self.in_play or (self._last is r and not self._touch_armed):
            return
        self._last = r
        self._touch_armed = False
        b = self._ball_off
        self._events.append(
            BallEvent(
                kind="TOUCH",
                tick=self.tick,
                team=r.team,
                robot=r.n,
                x=s[b],
                y=s[b + 1],
                last_team=r.team,
                last_robot=r.n,
            )
        )

    def _event(self, kind: str, team: str, x: float, y: float, robot: int = -1) -> None:
        if not self.in_play:
            return
        last = self._last
        self._events.append(
            BallEvent(
                kind=kind,
                tick=self.tick,
                team=team,
                robot=robot,
                x=x,
                y=y,
                last_team=last.team if last else "",
                last_robot=last.n if last else -1,
            )
        )

    def _line_events(self, s: list[float]) -> None:
        if self._dead:
            return
        b = self._ball_off
        x, y = s[b], s[b + 1]
        ax, ay = abs(x), abs(y)
        if not self._airborne and ax < self._half_len:
            self._cross_high = False
        if self._out:
            if ax <= self._half_len and ay <= self._half_wid:
                self._out = False
        elif ax > self._half_len + self._ball_r:
            self._out = True
            attacker = "a" if (1 if x > 0 else -1) == self.attack_dir_a else "b"  # of the goal on this side
            if ay < self._half_goal and not self._cross_high:
                self._event("GOAL", attacker, x, y)
                self._stop_in_goal()
                return
            self._event("GOAL_LINE", other_team(attacker), x, y)  # team: the defender
        elif ay > self._half_wid + self._ball_r:
            self._out = True
            self._event("TOUCH_LINE", "", x, y)
        anchor = self._anchor
        if self._out or self._airborne or not self.in_play:
            self._anchor = None
            self._idle_ticks = 0
            if not self._out:
                self._idle_fired = False
            return
        if anchor is None or math.hypot(x - anchor[0], y - anchor[1]) > self._progress_radius:
            self._anchor = (x, y)
            self._idle_ticks = 0
            self._idle_fired = False
            return
        self._idle_ticks += 1
        if not self._idle_fired and self._idle_ticks * self._dt >= self.no_progress_s - 1e-9:
            self._idle_fired = True
            self._event("NO_PROGRESS", "", x, y)

    def stop_play(self) -> None:
        """The referee stopped the game: no touches, events or no-progress clock until `start_play`."""
        self.in_play = False

    def start_play(self) -> None:
        """START: the ball is free, and the next touch is reported whoever makes it."""
        self.in_play = True
        self._pin = None
        self._touch_armed = True
        self._idle_ticks = 0
        self._idle_fired = False
        self._anchor = None
