"""The referee's set pieces: positioning for a restart, the wall and the mark, and keeping the distance.

* referee: stands still on STOP-like commands, positions for set pieces
  (own team: one robot goes behind the ball; opponents keep `setpiece_distance`
  from the spot) and plays on START;

This is a team's side of a set piece. The rules' side (where the ball is put,
the distances each team keeps, where the engine moves a robot that did not, and
`Restarts`, which carries the referee's commands out) is rules/setpieces.py;
the table of rules is docs/rules.md.
"""

from __future__ import annotations

import math
from math import atan2, cos, hypot, sin

from arena.navigation.frames import wrap_angle
from arena.schemas.messages import Cmd, Order
from arena.strategies import skills as S
from arena.strategies.iris.params import WALL_PIECES, Vec


class SetPieceMixin:
    """Mixin of `IrisRobot`: set pieces."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def position_for_restart(self, tick: int, order: Order) -> Cmd:
        fixed = self._restart
        if fixed is not None and fixed[0] is order:  # the keeper's place or the home of this order, as last tick
            _, target, heading, extra = fixed
            return self.drive(tick, target, heading, self.p.cruise, extra_obstacles=extra)
        spot = (order.spot_x, order.spot_y)
        goal = self.plan.goal  # type: ignore[union-attr]
        if self.role == "goalkeeper":
            own = self.plan.own  # type: ignore[union-attr]
            target = (own[0] + order.attack_dir * self.p.skills.keeper_depth, 0.0)
            self._restart = (order, target, S.angle_to(target, spot), ())
            return self.drive(tick, target, self._restart[2], self.p.cruise)
        ours = order.command_team in (self.team, "")
        if ours and self.is_taker(order, spot):
            behind = order.command_team == self.team and order.command == "DROP_BALL"
            gap = self.p.setpiece_behind if order.command_team == self.team or behind else 1.0
            # S.behind_point(spot, goal, gap) and S.angle_to(target, goal) written out (the same operations): the
            # taker asks every tick of the restart
            a = atan2(goal[1] - spot[1], goal[0] - spot[0])
            tx, ty = spot[0] - gap * cos(a), spot[1] - gap * sin(a)
            return self.drive(tick, (tx, ty), atan2(goal[1] - ty, goal[0] - tx), self.p.cruise, extra_obstacles=(spot,))
        if self.p.advance and order.command_team not in (self.team, "") and order.command in WALL_PIECES:
            target = self.setpiece_defense(order, spot)
            if target is not None:
                x, y, _ = self.view.pose  # type: ignore[misc]
                keep = self.p.setpiece_distance + self.p.wall_margin
                sx, sy = spot
                if hypot(x - sx, y - sy) < keep - 0.1:  # S.dist((x, y), spot)
                    # Inside the 2 m circle: out of it first, away from the spot but turned (by up to
                    # `wall_exit_turn`) towards the target, so that it leaves on the way round to it.
                    a = S.angle_to(spot, (x, y)) if S.dist((x, y), spot) > 1e-6 else S.angle_to(spot, target)
                    turn = wrap_angle(S.angle_to(spot, target) - a)
                    a += S.clamp(turn, -self.p.wall_exit_turn, self.p.wall_exit_turn)
                    target = (spot[0] + keep * math.cos(a), spot[1] + keep * math.sin(a))
                heading = atan2(sy - target[1], sx - target[0])  # S.angle_to(target, spot)
                return self.drive(tick, target, heading, self.p.cruise, extra_obstacles=(spot,))
        home = self.home(order, spot)
        keep = self.p.setpiece_distance + 0.2 if order.command_team != self.team else 1.2
        sx, sy = spot
        d = hypot(home[0] - sx, home[1] - sy)  # S.dist(home, spot)
        if d < keep:
            own = self.plan.own  # type: ignore[union-attr]
            a = S.angle_to(spot, home) if d > 1e-6 else S.angle_to(spot, own)
            home = self.inside((sx + keep * math.cos(a), sy + keep * math.sin(a)), margin=-0.2)
        heading = atan2(sy - home[1], sx - home[0])  # S.angle_to(home, spot)
        if not ours and not (self.p.advance and order.command in WALL_PIECES):  # no taker nor wall: fixed for the order
            self._restart = (order, home, heading, (spot,))
        return self.drive(tick, home, heading, self.p.cruise, extra_obstacles=(spot,))

    def setpiece_defense(self, order: Order, spot: Vec) -> Vec | None:
        """Advance defense at the opponents' set piece: Fig. 7b before the ball is in play.

        The outfield robot nearer the wall point stands on the kick line from
        the spot to our goal centre, `setpiece_distance` + `wall_margin` from
        the spot (the block of Fig. 7b at the distance the rules allow, never
        nearer our goal centre than `retreat_radius` less 1 m); the other marks the
        opponent nearest our goal other than the taker goal-side
        (`arena.strategies.skills.mark_point`), kept out of the 2 m circle too. None: no mark
        for it (it takes its usual place).
        """
        own = self.plan.own  # type: ignore[union-attr]
        keep = self.p.setpiece_distance + self.p.wall_margin
        d = hypot(spot[0] - own[0], spot[1] - own[1])  # S.dist(spot, own), written out: the wall asks every tick
        r = max(min(self.p.skills.retreat_radius - 1.0, d), d - keep)
        a = atan2(spot[1] - own[1], spot[0] - own[0])  # S.angle_to(own, spot)
        wall = self.inside((own[0] + r * math.cos(a), own[1] + r * math.sin(a)), margin=-0.3)
        if self._walls(order, wall):
            return wall
        best, found = self.p.mark_zone + 1.0, None
        ox, oy = own
        sx, sy = spot
        for o in self.view.opponents:
            dd = hypot(o[0] - ox, o[1] - oy)  # S.dist(o, own)
            if hypot(o[0] - sx, o[1] - sy) > 1.0 and dd < best:  # S.dist(o, spot)
                best, found = dd, o
        if found is None:
            return None
        mark = S.mark_point(found, own, self.p.skills.mark_distance)
        if hypot(mark[0] - spot[0], mark[1] - spot[1]) < keep:  # S.dist(mark, spot)
            b = S.angle_to(spot, mark)
            mark = (spot[0] + keep * math.cos(b), spot[1] + keep * math.sin(b))
        return self.inside(mark, margin=-0.3)

    def _walls(self, order: Order, wall: Vec) -> bool:
        """`setpiece_defense`: this robot is the outfield robot nearest the wall point (robot number breaks ties);
        static roles: of those whose Fig. 5 area holds it."""
        if not self.in_area(order, wall):
            return False
        x, y, _ = self.view.pose  # type: ignore[misc]
        wx, wy = wall
        mine, me = hypot(x - wx, y - wy), self.n  # S.dist((x, y), wall)
        dynamic = self.p.dynamic  # dynamic roles: `in_area` holds for all, not asked per teammate
        for n, (mx, my, _) in self.view.mates.items():
            if n != 0 and (dynamic or self.in_area(order, wall, n)):
                dm = hypot(mx - wx, my - wy)
                if not (dm > mine or dm == mine and n > me):  # not (dm, n) > (mine, me)
                    return False
        return True

    def is_taker(self, order: Order, spot: Vec) -> bool:
        """The outfield robot of ours nearest the spot takes the set piece (robot number breaks ties);
        static roles: of those whose Fig. 5 area holds the spot."""
        if not self.in_area(order, spot):
            return False
        x, y, _ = self.view.pose  # type: ignore[misc]
        sx, sy = spot
        mine, me = hypot(x - sx, y - sy), self.n  # S.dist((x, y), spot)
        dynamic = self.p.dynamic
        for n, (mx, my, _) in self.view.mates.items():
            if n != 0:
                dm = hypot(mx - sx, my - sy)
                # (dm, n) < (mine, me); dynamic roles: `in_area` holds for all, not asked per teammate
                if (dm < mine or dm == mine and n < me) and (dynamic or self.in_area(order, spot, n)):
                    return False
        return True

    def keep_setpiece_distance(self, tick: int, order: Order, ball: Vec) -> bool:
        """After the opponents' set-piece START: stay away until the ball has moved or 2 s passed."""
        if order.command_team in (self.team, "") or self.role == "goalkeeper":
            return False
        fresh = tick - self.mem.command_since < self._ticks_2s
        return fresh and hypot(ball[0] - order.spot_x, ball[1] - order.spot_y) < 0.3  # S.dist(ball, spot)
