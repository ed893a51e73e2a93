"""Attack with the ball: basic (paper 2) and advance (Fig. 7a), passes and the attacker getting open.

- basic attack (paper 2, "Basic strategy algorithm"): the holder dribbles
  straight towards the goal and kicks from `basic_shoot_distance`, whatever
  stands in the way, at the side of the goal the keeper leaves open; a
  static defender at the edge of its area kicks the ball on to its attacker
  (a pass ahead of it, `pass_lead`), blocked line or not;
- advance attack (Fig. 7a): shoot within `advance_shoot_distance` only when
  the line to the goal is clear (`arena.strategies.skills.best_aim`, the clear aim point
  needing the least turn), and carry a decided shot through for
  `shot_commit`; pass to a teammate that has a clear shot; a defender feeds
  the attacker when the pass line is clear; with an opponent in the path,
  go round it in a circle with the body between it and the ball, on the side
  away from the near touch line (`arena.strategies.skills.circle_past`, eq. 1 motion), then
  goal-ward again; closed down (`pressure_range`), pass if it can; at the
  carry limit, pass or push the ball ahead; never a shot from beyond
  `advance_shoot_distance` (paper 2: "shoot when within shooting distance
  and the line to the goal is clear"); the attacker without the ball
  gets open for a pass and a shot (`arena.strategies.skills.open_point`);
"""

from __future__ import annotations

import math
from math import atan2, hypot

from arena.schemas.messages import Cmd, Order
from arena.strategies import skills as S
from arena.strategies.iris.params import Vec


class AttackMixin:
    """Mixin of `IrisRobot`: attack."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def basic_attack(self, tick: int, order: Order, ball: Vec, pos: Vec, goal: Vec, at_limit: bool) -> Cmd:
        """Paper 2, basic strategy: dribble towards the goal, kick from a set distance."""
        aim = (goal[0], self.open_side(goal[0]))
        px, py = pos  # S.dist and S.angle_to written out below: a holder asks every tick
        gx, gy = goal
        if hypot(px - gx, py - gy) < self.p.basic_shoot_distance:
            return self.turn_and_kick(tick, aim, self.p.kick_speed)
        if not self.p.dynamic and order.attack_dir * px > self.plan.area[1] - 0.3:  # type: ignore[union-attr]
            # A static robot may not leave its area (self.u > my_area's hi - 0.3): kick the ball on to the
            # attacker, else at the goal.
            target = self.feed_target(order)
            if target is not None:
                return self.pass_to(tick, target)
            return self.turn_and_kick(tick, aim, self.p.kick_speed)
        if at_limit:
            return self.turn_and_kick(tick, self.nudge_point(pos, goal, []), self.p.nudge_speed)
        return self.drive(tick, goal, atan2(gy - py, gx - px), self.p.dribble_speed, dribbler=True, avoid=False)

    def advance_attack(self, tick: int, order: Order, ball: Vec, pos: Vec, goal: Vec, at_limit: bool) -> Cmd:
        """Paper 2, Fig. 7a: feed the attacker, sidestep blockers with the back to them, shoot when clear."""
        opponents = self.view.opponents
        gx, gy = goal
        d_goal = hypot(pos[0] - gx, pos[1] - gy)  # S.dist(pos, goal)
        sp = self.p.skills
        if tick <= self.mem.shot_until:  # a shot once decided is carried through (the line may flicker)
            return self.turn_and_kick(tick, self.mem.shot_aim, self.p.kick_speed)
        aim = None  # the aim point with its clear flag (`S.best_aim`), asked for only where the answer is used
        if d_goal < self.p.advance_shoot_distance or d_goal < self.p.close_shot:
            aim, clear = self.shot_aim(pos, goal[0], opponents)
            if (d_goal < self.p.advance_shoot_distance and clear) or d_goal < self.p.close_shot:
                self.mem.shot_until, self.mem.shot_aim = tick + self._commit_ticks, aim
                return self.turn_and_kick(tick, aim, self.p.kick_speed)
        target = self.shooter_target(order, pos, goal)
        if target is not None:
            return self.pass_to(tick, target)
        if self.role == "defender":
            target = self.pass_target(order)
            if target is not None:
                return self.pass_to(tick, target)
        _, hi = self.my_area(order)
        if not self.p.dynamic and self.u(order, pos[0]) > hi - 0.3:  # static defender at the edge of its area
            return self.clear(tick, order, ball)
        held_long = (tick - self.mem.hold_since) * self.cfg.timing.dt > self.p.max_hold
        if at_limit or held_long:
            target = self.pass_target(order)
            if target is not None:
                return self.pass_to(tick, target)
            return self.turn_and_kick(tick, self.nudge_point(pos, goal, opponents), self.p.nudge_speed)
        keeper_zone = self.p.keeper_zone  # the keeper is no blocker
        field_players = [o for o in opponents if hypot(o[0] - gx, o[1] - gy) > keeper_zone]  # S.dist(o, goal)
        blocker = S.blocker_ahead(pos, goal, field_players, sp.path_corridor, sp.path_lookahead)
        if blocker is not None:
            if S.dist(blocker, pos) < self.p.pressure_range:
                # Closed down: no room left to go round; pass if there is any way (a shot was
                # taken above if one was on: only within `advance_shoot_distance`, paper 2).
                target = self.pass_target(order, any_mate=True)
                if target is not None:
                    return self.pass_to(tick, target)
            rot = self.mem.circle_rot if tick - self.mem.circle_tick <= 2 else 0.0
            way, heading, self.mem.circle_rot = S.circle_past(pos, blocker, goal, sp.sidestep, rot=rot)
            self.mem.circle_tick = tick
            return self.drive(tick, way, heading, self.p.dribble_speed, dribbler=True, avoid=False)
        if aim is None:
            aim, _ = self.shot_aim(pos, goal[0], opponents)
        ahead = (goal[0] - order.attack_dir * min(self.p.advance_shoot_distance - 0.5, d_goal), aim[1] * 0.5)
        face = atan2(aim[1] - pos[1], aim[0] - pos[0])  # S.angle_to(pos, aim)
        return self.drive(tick, ahead, face, self.p.dribble_speed, dribbler=True, avoid=False)

    def shot_aim(self, pos: Vec, goal_x: float, opponents: list[Vec]) -> tuple[Vec, bool]:
        """`S.best_aim` from `pos` for this robot's heading: the aim point and whether its line is clear."""
        heading = self.view.pose[2]  # type: ignore[index]
        return S.best_aim(pos, goal_x, self.goal_half, opponents, self.p.skills.clear_margin, heading=heading)

    def open_side(self, goal_x: float) -> float:
        """Basic aim: 0.6 of the goal half-width on the side away from the keeper."""
        keeper_y, best = 0.0, 1.5  # [m] only a robot this close to the goal centre counts as the keeper
        for ox, oy in self.view.opponents:
            dd = math.hypot(ox - goal_x, oy)
            if dd < best:
                best, keeper_y = dd, oy
        return -0.6 * self.goal_half if keeper_y > 0 else 0.6 * self.goal_half

    def pass_target(self, order: Order, any_mate: bool = False) -> Vec | None:
        """Where to pass: `pass_lead` ahead of an attacker ahead of us (any_mate: any outfield
        teammate not behind us), if the line there is clear."""
        x, y, _ = self.view.pose  # type: ignore[misc]
        d = order.attack_dir
        mates = self.plan.mates if any_mate else self.plan.attackers  # type: ignore[union-attr]
        for mx, my in mates:
            if d * (mx - x) <= (-0.5 if any_mate else 1.0) or S.dist((mx, my), (x, y)) < 1.0:
                continue
            lead = self.lead_point(order, (mx, my))
            if S.line_clear((x, y), lead, self.view.opponents, self.p.skills.clear_margin):
                return lead
        return None

    def shooter_target(self, order: Order, pos: Vec, goal: Vec) -> Vec | None:
        """Advance: a teammate (not the keeper) within shooting distance with a clear shot and a clear pass line."""
        opponents, margin = self.view.opponents, self.p.skills.clear_margin
        for n, (mx, my, _) in sorted(self.view.mates.items()):
            if n == 0 or S.dist((mx, my), goal) > self.p.advance_shoot_distance or S.dist((mx, my), pos) < 1.0:
                continue
            if not S.line_clear(pos, (mx, my), opponents, margin):
                continue
            if S.best_aim((mx, my), goal[0], self.goal_half, opponents, margin)[1]:
                return mx, my
        return None

    def lead_point(self, order: Order, mate: Vec) -> Vec:
        """`pass_lead` in front of a teammate, towards the goal: it runs onto the ball facing the goal."""
        goal = self.plan.goal  # type: ignore[union-attr]
        a = S.angle_to(mate, goal)
        return self.inside((mate[0] + self.p.pass_lead * math.cos(a), mate[1] + self.p.pass_lead * math.sin(a)), -0.5)

    def feed_target(self, order: Order) -> Vec | None:
        """Basic: an attacker ahead of us, clear line or not."""
        x, _, _ = self.view.pose  # type: ignore[misc]
        for mx, my in self.plan.attackers:  # type: ignore[union-attr]
            if self.u(order, mx) - self.u(order, x) > 0.5:
                return self.lead_point(order, (mx, my))
        return None
