"""Chase-and-shoot: the simple team play every strategy name plays for now.

The four strategy names of the paper (basic/advance x static/dynamic) are
registered here so that matches and tournaments can name them; until the
team-play work lands they share this behaviour:

* base station: fuses the ball from the freshest visible detection among the
  reports, relays the referee's command, and gives roles: robot 0 keeps goal,
  the field robot nearest the ball attacks, the others defend;
* goalkeeper: stays on its goal line following the ball's y, clears the ball
  when it is close;
* attacker: gets behind the ball on the line to the opponent goal, dribbles in
  and shoots from 6 m;
* defender: waits between the ball and its own goal, 1.6 m out.
"""

from __future__ import annotations

import math

from arena.runtime.config import MatchConfig
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, Sense, TeamPose
from arena.strategies.base import RobotContext, Strategy, TeamContext

PLAY_COMMANDS = frozenset({"START"})
SHOOT_RANGE = 6.0  # [m] distance to the goal centre from which the attacker shoots
KICK_SPEED = 6.0  # [m/s] same for every strategy, as in the paper
CRUISE = 2.5  # [m/s] navigation speed cap
DRIBBLE_SPEED = 1.2  # [m/s]
K_POS = 2.0  # [1/s] position gain
K_HEAD = 4.0  # [1/s] heading gain


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class SimpleTeam:
    def __init__(self, ctx: TeamContext):
        self.cfg = ctx.cfg
        self.team = ctx.team
        self.ball: tuple[float, float, int] | None = None  # x, y, tick seen
        self.poses: dict[int, tuple[float, float, float, int]] = {}

    def step(self, tick: int, reports: dict[int, Report], referee: Referee | None) -> dict[int, Order]:
        for n, rep in reports.items():
            self.poses[n] = (rep.pose.x, rep.pose.y, rep.pose.theta, rep.tick)
            if rep.ball.visible and (self.ball is None or rep.tick >= self.ball[2]):
                self.ball = (rep.ball.x, rep.ball.y, rep.tick)
        command, cteam, sx, sy, attack_dir, strategy = "STOP", "", 0.0, 0.0, 1, 1
        if referee is not None:
            command, cteam, sx, sy = referee.command, referee.command_team, referee.spot_x, referee.spot_y
            attack_dir = referee.attack_dir_a if self.team == "a" else -referee.attack_dir_a
            own, opp = (
                (referee.score_a, referee.score_b) if self.team == "a" else (referee.score_b, referee.score_a)
            )
            strategy = 1 if own == opp else (2 if own < opp else 3)
        roles = self._roles()
        own_poses = [TeamPose(robot=n, x=p[0], y=p[1], theta=p[2], age=tick - p[3]) for n, p in sorted(self.poses.items())]
        bx, by, bt = self.ball if self.ball is not None else (0.0, 0.0, -1)
        return {
            n: Order(
                tick=tick,
                robot=n,
                command=command,
                command_team=cteam,
                spot_x=sx,
                spot_y=sy,
                attack_dir=attack_dir,
                strategy=strategy,
                role=roles[n],
                own=own_poses,
                ball_valid=self.ball is not None,
                ball_x=bx,
                ball_y=by,
                ball_age=tick - bt if bt >= 0 else 0,
            )
            for n in range(self.cfg.robots)
        }

    def _roles(self) -> dict[int, str]:
        roles = {n: "defender" for n in range(self.cfg.robots)}
        roles[0] = "goalkeeper"
        if self.ball is not None:
            field = [n for n in range(1, self.cfg.robots) if n in self.poses]
            if field:
                bx, by, _ = self.ball
                nearest = min(field, key=lambda n: (self.poses[n][0] - bx) ** 2 + (self.poses[n][1] - by) ** 2)
                roles[nearest] = "attacker"
        elif self.cfg.robots > 1:
            roles[1] = "attacker"
        return roles


class SimpleRobot:
    def __init__(self, ctx: RobotContext):
        self.cfg: MatchConfig = ctx.cfg
        self.team = ctx.team
        self.n = ctx.n
        self.half_length = ctx.cfg.field.length / 2.0
        self.goal_half = ctx.cfg.field.goal_width / 2.0
        self.role = "goalkeeper" if ctx.n == 0 else "attacker"

    # ------------------------------------------------------------------ report
    def report(self, tick: int, sense: Sense | None) -> Report:
        if sense is None:
            return Report(tick=tick, robot=self.n, pose=Pose(x=0.0, y=0.0, theta=0.0), role=self.role)
        return Report(
            tick=tick,
            robot=self.n,
            pose=sense.pose,
            ball=sense.ball,
            robots=sense.robots,
            has_ball=sense.has_ball,
            role=self.role,
        )

    # -------------------------------------------------------------------- step
    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        if sense is None or order is None or order.command not in PLAY_COMMANDS:
            return Cmd(tick=tick)
        self.role = order.role or self.role
        if sense.ball.visible:
            bx, by = sense.ball.x, sense.ball.y
        elif order.ball_valid:
            bx, by = order.ball_x, order.ball_y
        else:
            return self._turn(tick, sense, 0.6)  # look around for the ball
        p = sense.pose
        goal_x = order.attack_dir * self.half_length  # opponent goal centre
        own_x = -goal_x
        if self.role == "goalkeeper":
            ty = max(-self.goal_half + 0.2, min(self.goal_half - 0.2, by))
            tx = own_x + math.copysign(0.35, goal_x)
            face = math.atan2(by - p.y, bx - p.x)
            near = math.hypot(bx - p.x, by - p.y) < 0.45
            kick = KICK_SPEED if near and abs(_wrap(face - p.theta)) < 0.5 else 0.0
            return self._goto(tick, p, tx, ty, face, CRUISE, dribbler=False, kick=kick)
        if self.role == "defender":
            gx, gy = own_x, 0.0
            d = math.hypot(bx - gx, by - gy) or 1.0
            r = min(1.6, d * 0.5)
            tx, ty = gx + (bx - gx) / d * r, gy + (by - gy) / d * r
            return self._goto(tick, p, tx, ty, math.atan2(by - p.y, bx - p.x), CRUISE)
        # attacker: aim at the half of the goal mouth the keeper leaves open
        aim_y = self._open_corner(sense, goal_x)
        to_goal = math.atan2(aim_y - by, goal_x - bx)
        d_ball = math.hypot(bx - p.x, by - p.y)
        aim = math.atan2(aim_y - p.y, goal_x - p.x)  # robot -> aim point
        facing = abs(_wrap(aim - p.theta)) < 0.2
        in_front = d_ball < 0.42 and abs(_wrap(math.atan2(by - p.y, bx - p.x) - p.theta)) < 0.3
        if (sense.has_ball or in_front) and facing and math.hypot(goal_x - p.x, p.y) < SHOOT_RANGE:
            return Cmd(tick=tick, dribbler=True, kick_speed=KICK_SPEED)
        if sense.has_ball:
            return self._goto(tick, p, goal_x, aim_y, aim, DRIBBLE_SPEED, dribbler=True)
        # Get behind the ball on its line to the goal, a little off to one side
        # so that two attackers do not meet head-on.
        side = 0.15 if self.team == "a" else -0.15
        behind_x = bx - 0.35 * math.cos(to_goal) - side * math.sin(to_goal)
        behind_y = by - 0.35 * math.sin(to_goal) + side * math.cos(to_goal)
        dx, dy = behind_x - p.x, behind_y - p.y
        if dx * dx + dy * dy < 0.2**2 and abs(_wrap(to_goal - p.theta)) < 0.4:
            return self._goto(tick, p, bx, by, to_goal, 1.5, dribbler=True)
        return self._goto(tick, p, behind_x, behind_y, to_goal, CRUISE, dribbler=True)

    def _open_corner(self, sense: Sense, goal_x: float) -> float:
        """y of the aim point: 0.6 of the half-width, on the side away from the keeper."""
        other = "b" if self.team == "a" else "a"
        keeper_y = 0.0
        best = 1.5  # [m] only a robot this close to the goal centre counts as the keeper
        for r in sense.robots:
            if r.team == other:
                d = math.hypot(r.x - goal_x, r.y)
                if d < best:
                    best, keeper_y = d, r.y
        return -0.6 * self.goal_half if keeper_y > 0 else 0.6 * self.goal_half

    def _turn(self, tick: int, sense: Sense, omega: float) -> Cmd:
        return Cmd(tick=tick, omega=omega)

    def _goto(
        self,
        tick: int,
        p,
        tx: float,
        ty: float,
        heading: float,
        vmax: float,
        dribbler: bool = False,
        kick: float = 0.0,
    ) -> Cmd:
        vx, vy = K_POS * (tx - p.x), K_POS * (ty - p.y)
        v = math.hypot(vx, vy)
        if v > vmax:
            vx, vy = vx * vmax / v, vy * vmax / v
        c, s = math.cos(p.theta), math.sin(p.theta)
        omega = max(-2.5, min(2.5, K_HEAD * _wrap(heading - p.theta)))
        return Cmd(tick=tick, vx=c * vx + s * vy, vy=-s * vx + c * vy, omega=omega, dribbler=dribbler, kick_speed=kick)


def _make(name: str, alias: str, description: str) -> Strategy:
    return Strategy(name=name, make_team=SimpleTeam, make_robot=SimpleRobot, aliases=(alias,), description=description)


STRATEGIES = [
    _make("basic-static", "BS", "basic attack and defense, static roles (paper 2)"),
    _make("basic-dynamic", "BD", "basic attack and defense, dynamic roles (paper 2)"),
    _make("advance-static", "AS", "advance attack and defense, static roles (paper 2)"),
    _make("advance-dynamic", "AD", "advance attack and defense, dynamic roles (paper 2)"),
]
