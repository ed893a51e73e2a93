"""Ball handling, the same for all four strategies: who goes for the ball, getting it, kicking and passing it.

* the ball: the robot whose area holds the ball and that is nearest goes
  for it (paper 2: "pick up the ball"); the others take their positions
  (`home`); a robot that has just passed leaves the ball to the receiver;
* ball handling, the same for all four strategies: the MSL dribbling limit (a
  holder releases the ball before `carry_limit` of straight carry: pass, shot,
  or a push ahead that it catches again, `nudge_point`); a robot that loses
  the ball to a tackle steps off it for `regroup` (basic: aside; advance:
  goal-side, back onto the kick line) instead of wrestling for it; a holder
  pinned for `stall_hold` plays the ball on (`unstall`).
"""

from __future__ import annotations

import math
from math import cos, hypot, sin

from arena.navigation.frames import wrap_angle
from arena.schemas.messages import Cmd, Order
from arena.strategies import skills as S
from arena.strategies.iris.params import Vec


class HandlingMixin:
    """Mixin of `IrisRobot`: the ball."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def is_chaser(self, order: Order, ball: Vec) -> bool:
        """Nearest to the ball among our outfield robots whose area holds it (a fresh passer leaves it)."""
        mem = self.mem
        bu = order.attack_dir * ball[0]  # self.u(order, ball[0])
        lo, hi = self.plan.area  # type: ignore[union-attr]
        if (self.tick - mem.passed_at) * self._dt < self.p.pass_rest:
            mem.chasing = False
            return False
        if not lo - 0.3 <= bu <= hi + 0.3:
            mem.chasing = False
            return False
        x, y, _ = self.view.pose  # type: ignore[misc]
        bx, by = ball
        mine = hypot(x - bx, y - by) - (self.p.chase_hysteresis if mem.chasing else 0.0)
        me = self.n
        area = self.plan.areas  # type: ignore[union-attr]
        for n, (mx, my, _) in self.view.mates.items():
            if n == 0 or n not in area:
                continue
            mlo, mhi = area[n]
            if mlo - 0.3 <= bu <= mhi + 0.3:
                dm = hypot(mx - bx, my - by)
                if dm < mine or dm == mine and n < me:  # (dm, n) < (mine, me)
                    mem.chasing = False
                    return False
        mem.chasing = True
        return True

    def get_ball(self, tick: int, ball: Vec, target: Vec) -> Cmd:
        """Catch the ball so that it can then be pushed towards `target`."""
        p = self.p
        sp = p.skills
        x, y, th = self.view.pose  # type: ignore[misc]
        bx, by = ball
        to_ball = math.atan2(by - y, bx - x)  # S.angle_to(pos, ball)
        d = hypot(x - bx, y - by)  # S.dist(pos, ball)
        if d < self._near_ball and (
            S.lined_up((x, y), ball, target, sp.capture_lane) or abs(wrap_angle(to_ball - th)) < 0.35
        ):
            return self.drive(tick, ball, to_ball, p.approach_speed, dribbler=True, avoid=False)
        a = math.atan2(target[1] - by, target[0] - bx)  # S.angle_to(ball, target) ...
        off = sp.behind_ball  # ... for S.behind_point(ball, target, behind_ball)
        hx, hy = self.half_length + 0.1, self.half_width + 0.1  # self.inside(..., margin=0.1), inlined
        px, py = bx - off * cos(a), by - off * sin(a)
        px = -hx if px < -hx else hx if px > hx else px
        py = -hy if py < -hy else hy if py > hy else py
        heading = a if hypot(x - px, y - py) < 1.0 else to_ball
        return self.drive(tick, (px, py), heading, p.cruise, dribbler=d < 1.0, extra_obstacles=(ball,))

    def carrier(self, ball: Vec) -> Vec | None:
        """The opponent nearest the ball if it is close enough to have it (min of (distance, position))."""
        bx, by = ball
        best_d, best = math.inf, None
        for o in self.view.opponents:
            dd = hypot(o[0] - bx, o[1] - by)  # S.dist(o, ball)
            if best is None or dd < best_d or dd == best_d and o < best:
                best_d, best = dd, o
        if best is None:
            return None
        return best if best_d < self.p.possession_radius + 0.1 else None

    def nearest_opponent(self, x: float, y: float) -> Vec | None:
        best, found = math.inf, None
        for o in self.view.opponents:
            d = abs(o[0] - x) + abs(o[1] - y)
            if d < best:
                best, found = d, o
        return found

    def turn_and_kick(self, tick: int, aim: Vec, speed: float, *, is_pass: bool = False) -> Cmd:
        """Holding the ball: turn towards aim (slowly) and kick once facing it.

        The kick is taken once the ball would pass within `shot_spread` of aim,
        i.e. at a heading error below atan(shot_spread / distance), between
        `min_aim_tolerance` and `aim_tolerance`; passes allow twice the spread.
        """
        x, y, th = self.view.pose  # type: ignore[misc]
        want = S.angle_to((x, y), aim)
        spread = self.p.shot_spread * (2.0 if is_pass else 1.0)
        tol = S.clamp(math.atan2(spread, S.dist((x, y), aim)), self.p.min_aim_tolerance, self.p.aim_tolerance)
        # The kick leaves along the heading of the next tick, when the command applies.
        kick = speed if abs(wrap_angle(want - th - self.view.omega * self.cfg.timing.dt)) < tol else 0.0
        if kick:
            self.mem.kicked_at = tick
            if is_pass:
                self.mem.passed_at = tick
        # Turning on the spot; an opponent in contact would jam the turn, so edge away from it.
        spot = (x, y)
        near = self.nearest_opponent(x, y)
        if near is not None and S.dist(near, spot) < self.p.contact_range:
            a = S.angle_to(near, spot)
            spot = (x + 0.5 * math.cos(a), y + 0.5 * math.sin(a))
        return self.drive(
            tick, spot, want, self.p.separate_speed if spot != (x, y) else 0.0, dribbler=True, kick=kick, avoid=False
        )

    def pass_to(self, tick: int, target: Vec) -> Cmd:
        return self.turn_and_kick(tick, target, self.pass_speed(target), is_pass=True)

    def pass_speed(self, target: Vec) -> float:
        x, y, _ = self.view.pose  # type: ignore[misc]
        return S.pass_speed(S.dist((x, y), target), self.p.pass_arrive, self.cfg.ball.rolling_decel, self.p.kick_speed)

    def with_ball(self, tick: int, order: Order, ball: Vec) -> Cmd:
        x, y, _ = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        goal = self.plan.goal  # type: ignore[union-attr]
        mem = self.mem
        carry_from = mem.carry_from  # S.dist(pos, carry_from) written out: a holder asks every tick
        carried = hypot(x - carry_from[0], y - carry_from[1]) if carry_from is not None else 0.0
        at_limit = carried > self.p.carry_limit
        if (tick - mem.hold_since) * self._dt > self.p.stall_hold:  # _dt: cfg.timing.dt
            return self.unstall(tick, order)
        if self.p.advance:
            return self.advance_attack(tick, order, ball, pos, goal, at_limit)
        return self.basic_attack(tick, order, ball, pos, goal, at_limit)

    def unstall(self, tick: int, order: Order) -> Cmd:
        """Held the ball too long (pinned against an opponent): play it on along the heading,
        unless that points towards our goal."""
        x, y, th = self.view.pose  # type: ignore[misc]
        if math.cos(th) * order.attack_dir > -0.3:
            self.mem.kicked_at = tick
            return self.drive(tick, (x, y), th, 0.0, dribbler=True, kick=self.p.unstall_speed, avoid=False)
        return self.turn_and_kick(tick, self.plan.goal, self.p.unstall_speed)  # type: ignore[union-attr]

    def nudge_point(self, pos: Vec, goal: Vec, opponents: list[Vec]) -> Vec:
        """Where to push the ball ahead at the carry limit: goal-ward, turned away from the nearest opponent."""
        a = S.angle_to(pos, goal)
        near = min(opponents, key=lambda o: S.dist(o, pos), default=None)
        if near is not None and S.dist(near, pos) < 2.0:
            off = wrap_angle(S.angle_to(pos, near) - a)
            a -= math.copysign(0.6, off) if abs(off) < 1.2 else 0.0
        return pos[0] + 2.0 * math.cos(a), pos[1] + 2.0 * math.sin(a)
