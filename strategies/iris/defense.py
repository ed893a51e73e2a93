"""Without the ball: basic and advance defense (Fig. 7b).

- basic defense: the robot whose area holds the ball tries to catch it and
  grab it from the opponent (`get_ball`), the others wait at home;
- advance defense (Fig. 7b): the outfield robot that gets onto the kick line
  soonest (`is_blocker`) meets an opponent carrying the ball within
  `block_zone` of our goal on its estimated kick line (the ball's line to our
  goal centre), 1 m from it, retreating with it down to 3 m from our goal
  centre and then following the ball (`arena.strategies.skills.block_point`), tracking the
  line at `block_gain`, and takes the ball within 0.5 m from the kick line;
  the other marks the opponent nearest our goal goal-side when it is within
  `mark_zone` of our goal (man-to-man marking, the paper's stated approach;
  the attacker only while the ball is within `drop_back` of our goal); at
  the opponents' free kicks, throw-ins, corners and kick-offs one robot
  walls the kick line 2.2 m from the spot and the other marks
  (`setpiece_defense`).
"""

from __future__ import annotations

import math
from math import atan2, hypot

from arena.navigation.frames import wrap_angle
from arena.schemas.messages import Cmd, Order
from arena.strategies import skills as S
from arena.strategies.iris.params import Vec


class DefenseMixin:
    """Mixin of `IrisRobot`: defense."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def without_ball(self, tick: int, order: Order, ball: Vec) -> Cmd:
        view, p = self.view, self.p
        x, y, _ = view.pose  # type: ignore[misc]
        goal = self.plan.goal  # type: ignore[union-attr]
        if (tick - self.mem.lost_at) * self._dt < p.regroup and self.carrier(ball) is not None:
            pos = (x, y)
            # Lost the ball to a tackle: step back instead of wrestling for it, then challenge again;
            # basic: aside; advance: goal-side, onto the carrier's kick line (Fig. 7b).
            if S.dist(pos, ball) < self.p.regroup_clear:  # first get the body off the ball, straight back
                a = S.angle_to(ball, pos)
                back = (x + 0.5 * math.cos(a), y + 0.5 * math.sin(a))
            elif self.p.advance:
                back = S.behind_point(ball, goal, self.p.regroup_distance)
            else:
                back = S.aside_point(ball, self.plan.own, pos, self.p.regroup_distance)  # type: ignore[union-attr]
            return self.drive(tick, back, S.angle_to(pos, ball), self.p.cruise, avoid=False)
        attacking = self.plan.attacking  # type: ignore[union-attr]
        if attacking:
            bx, by = ball
            for mx, my, _ in view.mates.values():
                if hypot(mx - bx, my - by) < 0.4:  # a teammate has the ball
                    if p.advance and self.role == "attacker":
                        home = self.support_point(order, ball)
                    else:
                        home = self.home(order, ball)
                    return self.drive(tick, home, atan2(by - home[1], bx - home[0]), p.cruise)  # S.angle_to(home, ball)
        chaser = self.is_chaser(order, ball)
        if p.advance and not attacking:
            cmd = self.advance_defense(tick, order, ball, (x, y), chaser)
            if cmd is not None:
                return cmd
        if chaser:
            return self.get_ball(tick, ball, goal)
        home = self.home(order, ball)
        return self.drive(tick, home, atan2(ball[1] - home[1], ball[0] - home[0]), p.cruise)  # S.angle_to(home, ball)

    def advance_defense(self, tick: int, order: Order, ball: Vec, pos: Vec, chaser: bool) -> Cmd | None:
        """Paper 2, Fig. 7b, for an outfield robot while the team defends; None: play the ball as usual.

        An opponent carrying the ball within `block_zone` of our goal is met by
        the robot that gets onto its kick line soonest (`is_blocker`) on that
        line (the ball's line to our goal centre), `block_distance` (1 m) from
        the carrier and no closer than `retreat_radius` (3 m) to our goal
        centre, facing the ball (`arena.strategies.skills.block_point`); within
        `take_distance` (0.5 m) of the ball it takes it, straight from the kick
        line (within `take_angle` of it). It drives there straight once goal-side of the carrier
        (steering round it only to get goal-side) and with the tracking gain
        `block_gain`, so that it stays on the line while the carrier turns to
        aim or circles. The other outfield robot marks the most dangerous
        other opponent goal-side (man-to-man marking, `arena.strategies.skills.mark_point`),
        which also cuts the pass to it: the defender always, the attacker while
        the ball is within `drop_back` of our goal (both field robots defend
        when the team has lost the ball deep in its half; paper 2: "defender
        robots ... will always block opposing attacker to score goal").
        """
        sp = self.p.skills
        own = self.plan.own  # type: ignore[union-attr]
        carrier = self.carrier(ball)
        ox, oy = own
        # [m] the carrier to our goal centre, S.dist(carrier, own)
        d_carrier = hypot(carrier[0] - ox, carrier[1] - oy) if carrier is not None else 0.0
        if carrier is not None and d_carrier < self.p.block_zone:
            block = S.block_point(carrier, own, sp, ball)
            if self.is_blocker(order, block, d_carrier - 0.2, own):
                # Within take_distance of the ball, take it, but only from the kick line: straight at the
                # ball from goal-side; going round the ball to get behind it would open the line to our goal.
                # S.dist and S.angle_to written out (the same operations): the blocker asks every tick
                bx, by = ball
                px, py = pos
                on_line = abs(wrap_angle(atan2(py - by, px - bx) - atan2(oy - by, ox - bx))) < self.p.take_angle
                if hypot(px - bx, py - by) < sp.take_distance and on_line:
                    return self.drive(
                        tick, ball, atan2(by - py, bx - px), self.p.approach_speed, dribbler=True, avoid=False
                    )
                goal_side = hypot(px - ox, py - oy) < d_carrier - 0.2
                return self.drive(
                    tick,
                    block,
                    atan2(by - block[1], bx - block[0]),  # S.angle_to(block, ball)
                    self.p.cruise,
                    dribbler=True,
                    avoid=not goal_side,
                    gain=self.p.block_gain,
                )
        else:
            self.mem.blocking = False
            if chaser:
                return None
        bx, by = ball
        if self.role == "attacker" and hypot(bx - ox, by - oy) > self.p.drop_back:  # S.dist(ball, own)
            return None
        target = self.marking_target(order, carrier if carrier is not None else ball)
        if target is None:
            return None
        mark = S.mark_point(target, own, sp.mark_distance)
        # static roles: a mark outside its Fig. 5 area is not its job (`in_area` holds for all under dynamic roles)
        if not self.p.dynamic and not self.in_area(order, mark):
            return None
        return self.drive(tick, mark, atan2(by - mark[1], bx - mark[0]), self.p.cruise)  # S.angle_to(mark, ball)

    def is_blocker(self, order: Order, block: Vec, limit: float, own: Vec) -> bool:
        """Advance defense: of our outfield robots, the one that gets onto the kick line soonest blocks:
        the nearest to the block point, counting `behind_penalty` more for a robot farther than `limit` [m]
        (the carrier's distance to our goal centre `own` less 0.2 m: not goal-side of the carrier, it has to
        go round it) and `chase_hysteresis` less for the current blocker. Static roles: only robots whose
        Fig. 5 area holds the block point."""
        mem = self.mem
        if not self.p.dynamic and not self.in_area(order, block):  # dynamic roles: `in_area` holds for all
            mem.blocking = False
            return False
        penalty = self.p.behind_penalty
        bx, by = block
        ox, oy = own
        x, y, _ = self.view.pose  # type: ignore[misc]
        # cost(pt) = S.dist(pt, block) + (penalty if S.dist(pt, own) > limit else 0.0), inlined
        mine = hypot(x - bx, y - by) + (penalty if hypot(x - ox, y - oy) > limit else 0.0)
        mine -= self.p.chase_hysteresis if mem.blocking else 0.0
        me, dynamic = self.n, self.p.dynamic  # dynamic roles: `in_area` holds for all, not asked per teammate
        for n, (mx, my, _) in self.view.mates.items():
            if n != 0 and (dynamic or self.in_area(order, block, n)):
                cost = hypot(mx - bx, my - by) + (penalty if hypot(mx - ox, my - oy) > limit else 0.0)
                if not (cost > mine or cost == mine and n > me):  # not (cost, n) > (mine, me)
                    mem.blocking = False
                    return False
        mem.blocking = True
        return True

    def marking_target(self, order: Order, carrier: Vec) -> Vec | None:
        """The opponent other than the carrier nearest our goal, if it is within `mark_zone` of it."""
        ox, oy = self.plan.own  # type: ignore[union-attr]
        cx, cy = carrier
        best, found = self.p.mark_zone, None
        for o in self.view.opponents:
            if hypot(o[0] - cx, o[1] - cy) < 0.3:  # S.dist(o, carrier)
                continue
            d = hypot(o[0] - ox, o[1] - oy)  # S.dist(o, own)
            if d < best:
                best, found = d, o
        return found
