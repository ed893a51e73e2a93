"""The goalkeeper, robot 0 in all four strategies.

* goalkeeper (robot 0, all four strategies): guards the mouth and intercepts
  the predicted ball path (:func:`arena.strategies.skills.keeper_target`), clears balls that
  stop near it;
"""

from __future__ import annotations

import math
from math import hypot

from arena.schemas.messages import Cmd, Order
from arena.strategies import skills as S
from arena.strategies.iris.params import Vec


class KeeperMixin:
    """Mixin of `IrisRobot`: goalkeeper."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def goalkeeper(self, tick: int, order: Order, ball: Vec) -> Cmd:
        view = self.view
        if view.has_ball:
            return self.clear(tick, order, ball)
        own_x = self.plan.own[0]  # type: ignore[union-attr]
        x, y, _ = view.pose  # type: ignore[misc]
        bx, by = ball
        d_ball = hypot(x - bx, y - by)  # S.dist(pos, ball)
        near_goal = abs(bx - own_x) < self.cfg.field.penalty_area_depth and abs(by) < self._penalty_half_width
        vbx, vby = view.ball_vel
        if near_goal and hypot(vbx, vby) < 1.0:  # near our goal and slow: the keeper may take it
            opp = math.inf  # the nearest opponent's distance to the ball
            for ox, oy in view.opponents:
                dd = hypot(ox - bx, oy - by)
                if dd < opp:
                    opp = dd
            if d_ball < (opp if opp < 1.5 else 1.5):  # min(1.5, opp)
                return self.get_ball(tick, ball, self.plan.goal)  # type: ignore[union-attr]
        target, _ = S.keeper_target(ball, view.ball_vel, own_x, self.goal_half, self.p.skills)
        return self.drive(
            tick,
            target,
            math.atan2(by - y, bx - x),
            self.p.cruise,
            dribbler=d_ball < 1.0,
            avoid=False,
            gain=self.p.keeper_gain,
        )

    def clear(self, tick: int, order: Order, ball: Vec) -> Cmd:
        """Goalkeeper or cornered defender with the ball: pass to a free teammate, else kick upfield."""
        x, y, _ = self.view.pose  # type: ignore[misc]
        target = self.pass_target(order)
        if target is not None:
            return self.pass_to(tick, target)
        goal = self.plan.goal  # type: ignore[union-attr]
        aim = (goal[0], S.clamp(y, -2.0, 2.0))
        return self.turn_and_kick(tick, aim, self.p.kick_speed)
