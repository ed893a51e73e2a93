"""Where an outfield robot stands when it does not play the ball: its home in its area, and the advance attacker's
support point (open for a pass and a shot).
"""

from __future__ import annotations

import math

from arena.schemas.messages import Order
from arena.strategies import roles as R
from arena.strategies import skills as S
from arena.strategies.iris.params import Vec


class PositionsMixin:
    """Mixin of `IrisRobot`: positions off the ball."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def home(self, order: Order, ball: Vec) -> Vec:
        """Where a robot waits while it does not go for the ball, by role and team mode.

        Attacker: in attacking mode up the field, on the other side from the
        ball, to receive the ball; in defending mode just ahead of the ball, in
        its area, ready for a counter-attack. Defender: in attacking mode at
        `cover_depth` in its own half, following the ball's y a little; in
        defending mode between the ball and our goal, at most 3.2 m out.
        S2 (losing) pushes everyone 1 m up, S3 (winning) 1 m back.
        """
        # S.clamp, S.dist and S.angle_to written out (the same operations): an off-ball robot asks every tick
        lo, hi = self.plan.area  # type: ignore[union-attr]
        d = order.attack_dir
        bx, by = ball
        bu = d * bx
        strategy = order.strategy
        shift = 1.0 if strategy == R.S_OFFENSIVE else -1.0 if strategy == R.S_DEFENSIVE else 0.0
        attacking = self.plan.attacking  # type: ignore[union-attr]
        if self.role == "attacker":
            if attacking:
                ulo = lo + 1.5
                u, ulo, uhi = bu + 2.5 + shift, 1.0 if 1.0 > ulo else ulo, hi - 2.0  # max(lo + 1.5, 1.0)
                u = ulo if u < ulo else uhi if u > uhi else u
                yy = -1.5 if by > 0.5 else 1.5 if by < -0.5 else (1.5 if self.n % 2 else -1.5)
                return d * u, yy
            u, ulo, uhi = bu + 1.5 + shift, lo + 0.5, hi - 1.5
            u = ulo if u < ulo else uhi if u > uhi else u
            yy = -0.5 * by + (1.0 if by <= 0 else -1.0)
            yy = -2.5 if yy < -2.5 else 2.5 if yy > 2.5 else yy
            return d * u, yy
        if attacking:  # cover behind the play, little moved by the ball: the defender's area is its own half
            u, ulo, uhi = self.p.cover_depth + shift, lo + 1.5, hi - 0.3
            u = ulo if u < ulo else uhi if u > uhi else u
            return d * u, 0.25 * by
        ox, oy = self.plan.own  # type: ignore[union-attr]
        r, far = 3.2 + (0.0 if 0.0 > shift else shift), 0.5 * math.hypot(ox - bx, oy - by) + 1.0
        r = far if far < r else r  # min(3.2 + max(shift, 0.0), 0.5 * S.dist(own, ball) + 1.0)
        a = math.atan2(by - oy, bx - ox)
        hx, hy = ox + r * math.cos(a), oy + r * math.sin(a)
        u, ulo, uhi = d * hx, lo + 1.0, hi - 0.3
        u = ulo if u < ulo else uhi if u > uhi else u
        return d * u, hy

    def support_point(self, order: Order, ball: Vec) -> Vec:
        """Advance attack: get open for a pass and a shot (`arena.strategies.skills.open_point`), worked out once per order."""
        if self._support is not None and self._support[0] is self.order:
            return self._support[1]
        lo, hi = self.my_area(order)
        d = order.attack_dir
        bu = d * ball[0]
        us = {S.clamp(bu + k, max(lo + 1.0, 0.5), min(hi - 1.5, 4.5)) for k in (1.5, 3.0)}
        cands = [(d * u, yy) for u in sorted(us) for yy in (-1.5, 0.0, 1.5)]
        goal_x = self.plan.goal[0]  # type: ignore[union-attr]
        pt = S.open_point(ball, cands, self.view.opponents, goal_x, self.goal_half, self.p.skills.clear_margin)
        self._support = (self.order, pt)
        return pt
