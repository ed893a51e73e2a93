"""Example strategy plugin for soccer-arena: every robot stands on the line ball -> own goal.

Install it next to soccer-arena (``pip install -e examples/arena_wall``) and
play it with ``arena match --home wall --away AD``. It reuses the arena's
navigation (F-SFM) and relays the base station's fused ball to the robots.
It declares two parameters (`PARAMS`, ``arena strategies --params wall``),
which a match sets per team: ``arena match --home wall --away AD --param
a.spacing=1.0``.
"""

from __future__ import annotations

import math

from arena.navigation import get
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, Sense
from arena.strategies.base import Param, RobotContext, Strategy, TeamContext

PARAMS = (
    Param("spacing", default=1.2, low=0.5, high=2.5, unit="m", meaning="between robots along the wall"),
    Param(
        "cruise",
        default=2.0,
        low=0.5,
        high=4.0,
        unit="m/s",
        meaning="the robot slows down within cruise / 2 metres of its place on the wall",
    ),
)


class WallTeam:
    def __init__(self, ctx: TeamContext):
        self.team, self.robots = ctx.team, ctx.cfg.robots
        self.ball: tuple[float, float] | None = None

    def step(self, tick: int, reports: dict[int, Report], referee: Referee | None) -> dict[int, Order]:
        for rep in reports.values():
            if rep.ball.visible:
                self.ball = (rep.ball.x, rep.ball.y)
        command = referee.command if referee is not None else "STOP"
        attack = 1
        if referee is not None:
            attack = referee.attack_dir_a if self.team == "a" else -referee.attack_dir_a
        bx, by = self.ball or (0.0, 0.0)
        return {
            n: Order(
                tick=tick,
                robot=n,
                command=command,
                attack_dir=attack,
                ball_valid=self.ball is not None,
                ball_x=bx,
                ball_y=by,
            )
            for n in range(self.robots)
        }


class WallRobot:
    def __init__(self, ctx: RobotContext):
        self.n, self.half = ctx.n, ctx.cfg.field.length / 2
        self.nav = get("f-sfm")
        values = ctx.param_values(PARAMS)  # this team's values, checked, or the defaults
        self.spacing, self.cruise = values["spacing"], values["cruise"]

    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        if sense is None or order is None or order.command != "START" or not order.ball_valid:
            return Cmd(tick=tick)
        p = sense.pose
        gx = -order.attack_dir * self.half  # own goal centre
        a = math.atan2(order.ball_y, order.ball_x - gx)
        r = 0.6 + self.spacing * self.n
        tx, ty = gx + r * math.cos(a), r * math.sin(a)
        obstacles = [(o.x, o.y) for o in sense.robots]
        vx, vy = self.nav((p.x, p.y), (0.0, 0.0), (tx, ty), obstacles)
        k = min(1.0, 2.0 * math.hypot(tx - p.x, ty - p.y) / self.cruise)
        c, s = math.cos(p.theta), math.sin(p.theta)
        face = math.atan2(order.ball_y - p.y, order.ball_x - p.x)
        omega = max(-3.0, min(3.0, 4.0 * math.remainder(face - p.theta, 2 * math.pi)))
        return Cmd(tick=tick, vx=k * (c * vx + s * vy), vy=k * (-s * vx + c * vy), omega=omega)

    def report(self, tick: int, sense: Sense | None) -> Report:
        if sense is None:
            return Report(tick=tick, robot=self.n, pose=Pose(x=0.0, y=0.0, theta=0.0))
        return Report(tick=tick, robot=self.n, pose=sense.pose, ball=sense.ball, robots=sense.robots)


STRATEGY = Strategy(
    name="wall",
    make_team=WallTeam,
    make_robot=WallRobot,
    aliases=("W",),
    description="example plugin: a wall between the ball and the own goal",
    params=PARAMS,
)
