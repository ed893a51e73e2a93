"""Stuck robots: driven, yet in one place for `stuck_s` (docs/rules.md rule 25, REPAIR_OUT).

The engine asks every referee period (`StuckWatch.check`). A robot counts as
driven while its command asks for more than `DRIVEN_SPEED` of linear speed;
its clock restarts whenever it is not driven, gets more than `stuck_radius`
from where the clock started, or the ball is not in play (robots positioning
for a set piece may wait on each other). A stuck robot is reported once as
ROBOT_STUCK, and again only after another `stuck_s`. Pure function of the
physics state: no clock, no randomness.
"""

from __future__ import annotations

import math

from arena.config import MatchConfig
from arena.schemas.messages import BallEvent

DRIVEN_SPEED = 0.1  # [m/s] commanded linear speed above which a robot is trying to move


class StuckWatch:
    def __init__(self, cfg: MatchConfig):
        r = cfg.rules
        self.ticks = int(round(r.stuck_s / cfg.timing.dt)) if r.stuck_s > 0 else 0
        self.radius = r.stuck_radius
        self.anchor: dict[tuple[str, int], tuple[float, float, int]] = {}  # where and when its clock started

    def check(self, ph) -> list[BallEvent]:
        """ROBOT_STUCK for every robot of `ph` (a Physics) stuck as of its current tick."""
        if self.ticks <= 0:
            return []
        if not ph.in_play:
            self.anchor.clear()  # every clock restarts
            return []
        k, out, anchor, radius, hypot = ph.tick, [], self.anchor, self.radius, math.hypot
        # a parked robot's commanded speed is 0: it is never driven
        for st, speed in zip(ph.robot_states(), ph.commanded_speeds()):
            r = (st[0], st[1])
            if speed <= DRIVEN_SPEED:
                if anchor:
                    anchor.pop(r, None)
                continue
            x, y = st[2], st[3]
            a = anchor.get(r)
            if a is None or hypot(x - a[0], y - a[1]) > radius:
                anchor[r] = (x, y, k)
            elif k - a[2] >= self.ticks:
                out.append(BallEvent(kind="ROBOT_STUCK", tick=k, team=r[0], robot=r[1], x=x, y=y))
                anchor[r] = (x, y, k)
        return out
