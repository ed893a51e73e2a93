"""Chase-and-shoot: the simple baseline team play.

`STRATEGIES` offers it under the paper's four names; strategies/registry.py
decides which names it gets. The behaviour:

* base station: fuses the ball from the freshest visible detection among the
  reports, relays the referee's command, and gives roles: robot 0 keeps goal,
  the field robot nearest the ball attacks, the others defend;
* goalkeeper: stays on its goal line following the ball's y, clears the ball
  when it is close;
* attacker: gets behind the ball on the line to the opponent goal (going
  round the ball when it comes from the goal side), dribbles towards the half
  of the goal mouth the keeper leaves open and shoots along its heading once
  that crosses the goal mouth within 6 m: flat if nobody stands in the way,
  else a chip (a lob, ballistic z) that passes over the robots and the keeper
  and under the crossbar, if nobody is within 1 m ahead. It shoots rather
  than dribble past the MSL 3 m limit, and slows down behind robots ahead so
  as not to push them (docs/rules.md);
* defender: waits between the ball and its own goal, 1.6 m out.

Referee commands (docs/rules.md): robots play only under START. Under a set
piece (FREEKICK, GOALKICK, THROWIN, CORNER, PENALTY, DROP_BALL) they position
themselves: the taking team's attacker waits behind the ball spot on its line
to the goal, everybody else takes its usual place pushed out of a circle
around the spot, as big as the rules ask of it (the set-piece distance for
the opponents, the drop-ball distance for everyone) plus a margin; goalkeepers
stay home. Under KICKOFF (the engine has placed everyone), STOP and the
stages they stand still.
"""

from __future__ import annotations

import math

from arena.config import MatchConfig
from arena.navigation.frames import wrap_angle
from arena.rules import setpieces
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, RobotSeen, Sense, TeamPose
from arena.schemas.vocabulary import other_team
from arena.strategies.base import RobotContext, Strategy, TeamContext, report_of
from arena.strategies.roles import referee_fields

PLAY_COMMANDS = frozenset({"START"})
SETUP_COMMANDS = setpieces.SET_PIECES - {"KICKOFF"}  # robots position themselves for these
TAKE_STANDOFF = 0.6  # [m] the taker waits this far behind the ball spot, centre to centre
KEEP_MARGIN = 0.4  # [m] kept beyond the distance the rules ask
TEAMMATE_GAP = 1.0  # [m] the taker's teammates leave it this much room
DRIBBLE_MAX = 2.4  # [m] carried this far, the attacker shoots (MSL limit: 3 m)
SHOOT_RANGE = 6.0  # [m] distance to the goal centre from which the attacker shoots
KICK_SPEED = 8.0  # [m/s] same for every strategy, as in the paper
CRUISE = 2.5  # [m/s] navigation speed cap
DRIBBLE_SPEED = 1.2  # [m/s]
K_POS = 2.0  # [1/s] position gain
K_HEAD = 4.0  # [1/s] heading gain
AIM_FRACTION = 0.75  # [-] aim this fraction of the goal's half-width off centre, away from the keeper
AIM_TOLERANCE = 0.25  # [rad] heading error within which the attacker shoots
BEHIND = 0.35  # [m] approach point behind the ball, centre to centre
AROUND = 0.7  # [m] lateral offset of the way round the ball when on its wrong side
CAUTION_RANGE = 1.6  # [m] a robot this close ahead slows us down (no pushing)
CAUTION_SPEED = 0.8  # [m/s]
SHOT_CORRIDOR = 0.45  # [m] a robot centre this close to the shot line blocks it (half-diagonal + ball)
SHOT_MARGIN = 0.2  # [m] a shot must cross the goal line this far inside the posts
KEEPER_ZONE = 1.2  # [m] robots this close to the goal centre count as the keeper
FORCED_SHOT_ANGLE = 1.0  # [rad] at the dribbling limit, shoot only if facing the goal this well
CHIP_MIN, CHIP_MAX = 3.0, 5.0  # [m] flight to the goal line for a chip over the keeper
CHIP_CLEAR = 1.0  # [m] a chip is still too low to pass over a robot this close ahead
CHIP_MARGIN = 0.3  # [m] a chip must cross the goal line this far inside the posts
GRAVITY = 9.81  # [m/s^2]


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
        c = referee_fields(self.team, referee, default_attack_dir=1)
        roles = self._roles()
        own_poses = [
            TeamPose(robot=n, x=p[0], y=p[1], theta=p[2], age=tick - p[3]) for n, p in sorted(self.poses.items())
        ]
        bx, by, bt = self.ball if self.ball is not None else (0.0, 0.0, -1)
        return {
            n: Order(
                tick=tick,
                robot=n,
                **c,
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
        self.carry_from: tuple[float, float] | None = None  # [m] where the dribbler took the ball
        self.hold = ctx.cfg.robot.size / 2 + ctx.cfg.ball.radius  # [m] robot centre to a held ball's centre
        self.chip_height = (ctx.cfg.robot.height + ctx.cfg.field.goal_height) / 2  # [m] over robots, under the bar

    # ------------------------------------------------------------------ report
    def report(self, tick: int, sense: Sense | None) -> Report:
        return report_of(tick, self.n, sense, self.role)

    # -------------------------------------------------------------------- step
    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        if sense is None or order is None:
            return Cmd(tick=tick)
        self.role = order.role or self.role
        if order.command in SETUP_COMMANDS:
            return self._position(tick, sense, order)
        if order.command not in PLAY_COMMANDS:
            return Cmd(tick=tick)
        return self._play(tick, sense, order)

    def _position(self, tick: int, sense: Sense, order: Order) -> Cmd:
        """Set-piece positioning: the taker behind the spot, the others clear of it."""
        p = sense.pose
        sx, sy = order.spot_x, order.spot_y
        goal_x = order.attack_dir * self.half_length
        if self.role == "goalkeeper":
            return self._keep_goal(tick, p, sx, sy, -goal_x, kick=False)
        ours = order.command_team == self.team
        if ours and self.role == "attacker":
            to_goal = math.atan2(-sy, goal_x - sx)
            tx, ty = sx - TAKE_STANDOFF * math.cos(to_goal), sy - TAKE_STANDOFF * math.sin(to_goal)
            return self._goto(tick, p, tx, ty, to_goal, CRUISE)
        if order.command == "DROP_BALL":
            keep = self.cfg.rules.drop_ball_distance
        else:
            keep = TEAMMATE_GAP if ours else self.cfg.rules.setpiece_distance
        tx, ty = self._guard_point(sx, sy, -goal_x)
        tx, ty = _outside(tx, ty, sx, sy, keep + KEEP_MARGIN, -goal_x)
        return self._goto(tick, p, tx, ty, math.atan2(sy - p.y, sx - p.x), CRUISE)

    def _guard_point(self, bx: float, by: float, own_x: float) -> tuple[float, float]:
        """Between the ball and the own goal centre, 1.6 m out (at most half-way)."""
        d = math.hypot(bx - own_x, by) or 1.0
        r = min(1.6, d * 0.5)
        return own_x + (bx - own_x) / d * r, by / d * r

    def _keep_goal(self, tick: int, p, bx: float, by: float, own_x: float, kick: bool) -> Cmd:
        ty = max(-self.goal_half + 0.2, min(self.goal_half - 0.2, by))
        tx = own_x - math.copysign(0.35, own_x)
        face = math.atan2(by - p.y, bx - p.x)
        near = math.hypot(bx - p.x, by - p.y) < 0.45
        shot = KICK_SPEED if kick and near and abs(wrap_angle(face - p.theta)) < 0.5 else 0.0
        return self._goto(tick, p, tx, ty, face, CRUISE, dribbler=False, kick=shot)

    def _play(self, tick: int, sense: Sense, order: Order) -> Cmd:
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
            return self._keep_goal(tick, p, bx, by, own_x, kick=True)
        if self.role == "defender":
            tx, ty = self._guard_point(bx, by, own_x)
            return self._goto(tick, p, tx, ty, math.atan2(by - p.y, bx - p.x), CRUISE)
        # attacker: shoot if it can, else dribble to (or get behind the ball
        # towards) the half of the goal mouth the keeper leaves open
        self._track_carry(sense, p)
        if sense.has_ball or self._in_front(p, bx, by):
            shot = self._shot(sense, p, goal_x)
            if shot is not None:
                return Cmd(tick=tick, dribbler=True, kick_speed=shot[0], kick_lob=shot[1])
        aim_y = self._open_corner(sense, goal_x)
        aim = math.atan2(aim_y - p.y, goal_x - p.x)  # robot -> aim point
        to_goal = math.atan2(aim_y - by, goal_x - bx)
        if self._carried(p) > DRIBBLE_MAX:  # shoot rather than foul; release if facing away from the goal
            goalward = abs(wrap_angle(aim - p.theta)) < FORCED_SHOT_ANGLE
            return Cmd(tick=tick, dribbler=goalward, kick_speed=KICK_SPEED if goalward else 0.0)
        seen = sense.robots
        if sense.has_ball:
            return self._goto(tick, p, goal_x, aim_y, aim, DRIBBLE_SPEED, dribbler=True, avoid=seen)
        # Get behind the ball on its line to the goal, a little off to one side
        # so that two attackers do not meet head-on; from the ball's goal side,
        # go round it instead of pushing it back.
        ux, uy = math.cos(to_goal), math.sin(to_goal)
        side = 0.15 if self.team == "a" else -0.15
        if (p.x - bx) * ux + (p.y - by) * uy > -0.2:
            lateral = math.copysign(AROUND, (p.y - by) * ux - (p.x - bx) * uy)
            wx, wy = bx - BEHIND * ux - lateral * uy, by - BEHIND * uy + lateral * ux
            return self._goto(tick, p, wx, wy, to_goal, CRUISE, avoid=seen)
        behind_x = bx - BEHIND * ux - side * uy
        behind_y = by - BEHIND * uy + side * ux
        dx, dy = behind_x - p.x, behind_y - p.y
        if dx * dx + dy * dy < 0.2**2 and abs(wrap_angle(to_goal - p.theta)) < 0.4:
            return self._goto(tick, p, bx, by, to_goal, 1.5, dribbler=True, avoid=seen)
        return self._goto(tick, p, behind_x, behind_y, to_goal, CRUISE, dribbler=True, avoid=seen)

    def _track_carry(self, sense: Sense, p: Pose) -> None:
        if not sense.has_ball:
            self.carry_from = None
        elif self.carry_from is None:
            self.carry_from = (p.x, p.y)

    def _carried(self, p: Pose) -> float:
        """[m] straight-line distance from where the dribbler took the ball (the MSL measure)."""
        return math.hypot(p.x - self.carry_from[0], p.y - self.carry_from[1]) if self.carry_from else 0.0

    def _in_front(self, p: Pose, bx: float, by: float) -> bool:
        d = math.hypot(bx - p.x, by - p.y)
        return d < self.hold + 0.08 and abs(wrap_angle(math.atan2(by - p.y, bx - p.x) - p.theta)) < 0.3

    def _shot(self, sense: Sense, p: Pose, goal_x: float) -> tuple[float, bool] | None:
        """(kick speed [m/s], lob) for a shot along the current heading, or None.

        The ball leaves along the heading: it must cross the goal line inside
        the mouth. A flat shot needs a corridor clear of robots, the keeper
        included; a chip (lob) needs nobody within CHIP_CLEAR ahead and flies
        over everyone else, the keeper included, to cross the goal line at
        `chip_height`, between the robots' height and the crossbar; failing
        both, a flat shot past the keeper is still tried.
        """
        c, s = math.cos(p.theta), math.sin(p.theta)
        if c * goal_x <= 0.0:
            return None
        bx, by = p.x + self.hold * c, p.y + self.hold * s
        run = (goal_x - bx) / c  # [m] flight to the goal line along the heading
        y_cross = by + run * s
        if run > SHOOT_RANGE or abs(y_cross) > self.goal_half - SHOT_MARGIN:
            return None
        robots = sense.robots
        if _clear_shot(robots, bx, by, goal_x, y_cross):
            return KICK_SPEED, False
        speed = self._chip_speed(run)
        if speed is not None and abs(y_cross) < self.goal_half - CHIP_MARGIN:
            if _clear_shot(robots, bx, by, bx + CHIP_CLEAR * c, by + CHIP_CLEAR * s):
                return speed, True
        if _clear_shot(robots, bx, by, goal_x, y_cross, keeper_at=goal_x):
            return KICK_SPEED, False
        return None

    def _chip_speed(self, run: float) -> float | None:
        """Lob speed [m/s] that crosses the goal line `run` metres away at `chip_height`, if the kicker can.

        Ballistic flight at the launch angle a: z(x) = x tan a - g x^2 / (2 v^2 cos^2 a).
        """
        if not CHIP_MIN <= run <= CHIP_MAX:
            return None
        a = self.cfg.robot.lob_angle
        rise = run * math.tan(a) - self.chip_height
        if rise <= 0.0:
            return None
        v = math.sqrt(GRAVITY * run * run / (2.0 * rise)) / math.cos(a)
        return v if v <= self.cfg.robot.kick_max_speed else None

    def _open_corner(self, sense: Sense, goal_x: float) -> float:
        """y of the aim point: AIM_FRACTION of the half-width, on the side away from the keeper."""
        other = other_team(self.team)
        keeper_y = 0.0
        best = 1.5  # [m] only a robot this close to the goal centre counts as the keeper
        for r in sense.robots:
            if r.team == other:
                d = math.hypot(r.x - goal_x, r.y)
                if d < best:
                    best, keeper_y = d, r.y
        return (-AIM_FRACTION if keeper_y > 0 else AIM_FRACTION) * self.goal_half

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
        avoid: list[RobotSeen] | None = None,
    ) -> Cmd:
        """P control to (tx, ty) at most vmax, turning to `heading`; slow behind any robot of `avoid` ahead."""
        vx, vy = K_POS * (tx - p.x), K_POS * (ty - p.y)
        v = math.hypot(vx, vy)
        for r in avoid or ():
            dx, dy = r.x - p.x, r.y - p.y
            d = math.hypot(dx, dy)
            if d < CAUTION_RANGE and v > 0.0 and (dx * vx + dy * vy) > 0.5 * d * v:
                vmax = min(vmax, CAUTION_SPEED)
        if v > vmax:
            vx, vy = vx * vmax / v, vy * vmax / v
        c, s = math.cos(p.theta), math.sin(p.theta)
        omega = max(-2.5, min(2.5, K_HEAD * wrap_angle(heading - p.theta)))
        return Cmd(tick=tick, vx=c * vx + s * vy, vy=-s * vx + c * vy, omega=omega, dribbler=dribbler, kick_speed=kick)


def _clear_shot(
    robots: list[RobotSeen], bx: float, by: float, tx: float, ty: float, keeper_at: float | None = None
) -> bool:
    """No robot stands in the corridor from the ball to (tx, ty), except, if `keeper_at` is
    given, robots within KEEPER_ZONE of the goal centre (keeper_at, 0)."""
    dx, dy = tx - bx, ty - by
    length = math.hypot(dx, dy) or 1.0
    ux, uy = dx / length, dy / length
    for r in robots:
        if keeper_at is not None and math.hypot(r.x - keeper_at, r.y) < KEEPER_ZONE:
            continue
        along = (r.x - bx) * ux + (r.y - by) * uy
        if 0.0 < along < length and abs((r.y - by) * ux - (r.x - bx) * uy) < SHOT_CORRIDOR:
            return False
    return True


def _outside(x: float, y: float, cx: float, cy: float, radius: float, own_x: float) -> tuple[float, float]:
    """(x, y) pushed radially out of the circle (cx, cy, radius); from the centre, towards the own goal."""
    dx, dy = x - cx, y - cy
    d = math.hypot(dx, dy)
    if d >= radius:
        return x, y
    if d < 1e-6:
        dx, dy, d = own_x - cx, -cy, math.hypot(own_x - cx, cy) or 1.0
    return cx + dx / d * radius, cy + dy / d * radius


def _make(name: str, alias: str, description: str) -> Strategy:
    return Strategy(name=name, make_team=SimpleTeam, make_robot=SimpleRobot, aliases=(alias,), description=description)


STRATEGIES = [
    _make("basic-static", "BS", "basic attack and defense, static roles (paper 2)"),
    _make("basic-dynamic", "BD", "basic attack and defense, dynamic roles (paper 2)"),
    _make("advance-static", "AS", "advance attack and defense, static roles (paper 2)"),
    _make("advance-dynamic", "AD", "advance attack and defense, dynamic roles (paper 2)"),
]
