"""The IRIS team play of paper 2: basic/advance attack and defense x static/dynamic roles.

Four strategies, registered by name (:data:`STRATEGIES`): ``basic-static``
(BS), ``basic-dynamic`` (BD), ``advance-static`` (AS), ``advance-dynamic`` (AD).
All four share robot speed and kick speed (paper 2: "the speed of movement of
the robot and the kick on goal is made the same for all the algorithms").

Base station (`IrisTeam`), every comm period:

* fuses the reports into P_A, P_B, P_ball (eq. 5, :mod:`.world`);
* chooses S1/S2/S3 from the score (eq. 5, :func:`.roles.choose_strategy`);
* decides possession (inputs b and b-bar) and runs the role FSM of Fig. 6 with
  the areas and n_d = ceil(n/2) of eq. 6 (:mod:`.roles`); static roles never
  swap, dynamic roles swap with inputs a and d;
* relays the referee command C and sends one `Order` per robot.

Robot (`IrisRobot`), every tick, from its own `Sense` and the latest `Order`
(:class:`.world.RobotView`; robots never see ground truth):

* referee: stands still on STOP-like commands, positions for set pieces
  (own team: one robot goes behind the ball; opponents keep `setpiece_distance`
  from the spot) and plays on START;
* goalkeeper (robot 0): guards the mouth and intercepts the predicted ball path
  (:func:`.skills.keeper_target`), clears balls that stop near it;
* outfield: per role and team mode (Fig. 6 state in the order):
  - basic: the robot whose area holds the ball and that is nearest goes for
    it, dribbles it goal-ward and kicks from `basic_shoot_distance`; the
    others wait at their home positions;
  - advance attack (Fig. 7a): a defender holding the ball passes to the
    attacker; the attacker dribbles goal-ward, sidesteps an opponent in its
    path with its back to it, and shoots within `advance_shoot_distance` only
    when the line to the goal is clear;
  - advance defense (Fig. 7b): the nearest defender blocks the kick line of
    the opponent ball carrier 1 m from it, retreats down to 3 m from our goal
    centre, then follows the ball, and takes the ball within 0.5 m.
* every motion goes through a navigator of :mod:`arena.navigation` (F-SFM by
  default) so that robots steer round each other; the heading uses the PID of
  paper 1 eq. 15-16 (:mod:`arena.navigation.pid`), capped below the dribbler's
  3 rad/s while holding the ball.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from arena.navigation import PARAMS, get
from arena.navigation.fsfm import FSFMParams
from arena.navigation.pid import PIDParams, PIDState
from arena.navigation.pid import step as pid_step
from arena.navigation.sfm import SFMParams
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, Sense, TeamPose
from arena.strategies import roles as R
from arena.strategies import skills as S
from arena.strategies.base import RobotContext, Strategy, TeamContext
from arena.strategies.world import FusionParams, RobotView, TeamModel

Vec = tuple[float, float]

PLAY = "START"
SET_PIECES = frozenset({"KICKOFF", "FREEKICK", "GOALKICK", "THROWIN", "CORNER", "PENALTY", "DROP_BALL"})


@dataclass(frozen=True)
class IrisParams:
    advance: bool = False  # advance attack and defense (Fig. 7) instead of the basic play
    dynamic: bool = False  # dynamic roles (Fig. 6 inputs a and d) instead of static ones
    navigator: str = "f-sfm"  # arena.navigation name
    cruise: float = 2.5  # [m/s] travel speed, same for all four strategies
    dribble_speed: float = 1.5  # [m/s] while holding the ball
    approach_speed: float = 1.8  # [m/s] final approach onto the ball
    kick_speed: float = 6.5  # [m/s] shot speed, same for all four strategies
    basic_shoot_distance: float = 4.0  # [m] basic: kick from this distance to the goal centre
    advance_shoot_distance: float = 4.5  # [m] advance: shoot within this distance if the line is clear
    close_shot: float = 1.8  # [m] advance: shoot anyway this close
    pass_arrive: float = 1.5  # [m/s] ball speed at the receiver
    dribble_omega: float = 2.4  # [rad/s] turn-rate cap with the ball (the dribbler loses it at 3)
    max_omega: float = 5.0  # [rad/s] turn-rate cap without the ball
    aim_tolerance: float = 0.08  # [rad] heading error at which a shot or pass is taken
    k_pos: float = 2.5  # [1/s] arrival slow-down: speed <= k_pos * distance
    direct_range: float = 0.7  # [m] closer than this to a target the robot drives straight at it
    obstacle_range: float = 3.0  # [m] robots farther than this are no obstacle
    setpiece_distance: float = 2.0  # [m] opponents keep this far from a set-piece spot
    setpiece_behind: float = 0.5  # [m] the taker stands this far behind the ball
    chase_hysteresis: float = 0.4  # [m] the current chaser counts this much nearer
    possession_radius: float = 0.4  # [m] an opponent this close to the ball has it
    max_hold: float = 2.5  # [s] advance: act (shoot, pass or push ahead) after holding the ball this long
    carry_limit: float = 2.0  # [m] release the ball before this straight-line carry (MSL dribble limit 3 m)
    nudge_speed: float = 1.6  # [m/s] advance: kick the ball ahead to restart a carry at the limit
    push_guard: float = 0.9  # [m/s] closing speed cap towards a nearby opponent (pushing fouls above 1.5)
    push_guard_range: float = 1.0  # [m] opponents closer than this (centre to centre) get the cap
    heading_pid: PIDParams = PIDParams(k_p=6.0, k_i=0.0, k_d=2.0)  # paper 1 eq. 16 gains for 50 Hz
    skills: S.SkillParams = S.SkillParams()
    fusion: FusionParams = FusionParams()
    overlap: float = 1.0  # [m] defender/attacker areas overlap (paper 2)

    def nav_params(self):
        if self.navigator == "f-sfm":
            return FSFMParams(sfm=SFMParams(max_speed=self.cruise, robot_radius=0.5, sigma=0.3))
        defaults = PARAMS[self.navigator]()
        return type(defaults)(**{**{f: getattr(defaults, f) for f in defaults.__dataclass_fields__}, "max_speed": self.cruise})


class IrisTeam:
    """Base station brain: eq. 5 fusion, S1/S2/S3, Fig. 6 roles with the areas of eq. 6."""

    def __init__(self, ctx: TeamContext, p: IrisParams):
        self.cfg = ctx.cfg
        self.team = ctx.team
        self.p = p
        self.model = TeamModel(ctx.team, ctx.cfg.robots, ctx.cfg.sensor, ctx.cfg.timing.dt, p.fusion)
        self.area_params = R.AreaParams(field_length=ctx.cfg.field.length, overlap=p.overlap)
        self.roles = R.RoleAssigner(ctx.cfg.robots, p.dynamic, self.area_params)

    def possession(self, tick: int) -> tuple[str, int | None]:
        holder = self.model.holder()
        if holder is not None:
            return "own", holder
        ball = self.model.ball_xy(tick)
        if ball is None:
            return "", None
        opp = min((S.dist(o.xy, ball) for o in self.model.opponents), default=math.inf)
        own = min((S.dist((x, y), ball) for x, y, _, _ in self.model.own.values()), default=math.inf)
        if opp < self.p.possession_radius and opp < own:
            return "opponent", None
        return "", None

    def step(self, tick: int, reports: dict[int, Report], referee: Referee | None) -> dict[int, Order]:
        self.model.update(tick, reports)
        c = R.referee_fields(self.team, referee, default_attack_dir=1 if self.team == "a" else -1)
        command, cteam, attack_dir = c["command"], c["command_team"], c["attack_dir"]
        possession, holder = self.possession(tick)
        if command == PLAY:
            xy = {n: (v[0], v[1]) for n, v in self.model.own.items()}
            u = {n: attack_dir * v[0] for n, v in xy.items()}
            self.roles.update(possession, holder, u, xy)
        elif command in SET_PIECES and cteam:
            # A set piece gives the ball to one side: its team attacks (b), the other defends (b-bar).
            self.roles.update("own" if cteam == self.team else "opponent", None, {}, {})
        role_of = {0: "goalkeeper", **self.roles.roles()}
        own_poses = [
            TeamPose(robot=n, x=v[0], y=v[1], theta=v[2], age=tick - v[3], role=role_of.get(n, ""))
            for n, v in sorted(self.model.own.items())
        ]
        opponents = [TeamPose(robot=-1, x=o.x, y=o.y, age=tick - o.tick) for o in self.model.opponents]
        ball = self.model.ball_xy(tick)
        ball_age = self.model.ball.age(tick) if ball is not None else 0
        return {
            n: Order(
                tick=tick,
                robot=n,
                **c,
                role=role_of.get(n, "defender"),
                role_state=self.roles.state.get(n, 0),
                own=own_poses,
                opponents=opponents,
                ball_valid=ball is not None,
                ball_x=ball[0] if ball is not None else 0.0,
                ball_y=ball[1] if ball is not None else 0.0,
                ball_age=ball_age,
            )
            for n in range(self.cfg.robots)
        }


@dataclass
class _Memory:
    command: str = ""
    command_since: int = 0  # [tick] when the command in force changed
    chasing: bool = False
    carry_from: Vec | None = None  # [m] where this robot took the ball
    hold_since: int = 0  # [tick] when it took the ball
    pid: PIDState = field(default_factory=PIDState)


class IrisRobot:
    """Robot brain: perception, skills and the referee, for every role."""

    def __init__(self, ctx: RobotContext, p: IrisParams):
        cfg = ctx.cfg
        self.cfg = cfg
        self.team = ctx.team
        self.n = ctx.n
        self.p = p
        self.half_length = cfg.field.length / 2.0
        self.half_width = cfg.field.width / 2.0
        self.goal_half = cfg.field.goal_width / 2.0
        self.view = RobotView(ctx.team, ctx.n, cfg.sensor, cfg.timing.dt, p.fusion)
        self.nav = get(p.navigator)
        self.nav_params = p.nav_params()
        self.area_params = R.AreaParams(field_length=cfg.field.length, overlap=p.overlap)
        self.mem = _Memory()
        self.role = "goalkeeper" if ctx.n == 0 else ""
        self.order: Order | None = None

    # ------------------------------------------------------------------ report
    def report(self, tick: int, sense: Sense | None) -> Report:
        if sense is None:
            pose = self.view.pose or (0.0, 0.0, 0.0)
            return Report(tick=tick, robot=self.n, pose=Pose(x=pose[0], y=pose[1], theta=pose[2]), role=self.role)
        return Report(
            tick=tick, robot=self.n, pose=sense.pose, ball=sense.ball, robots=sense.robots,
            has_ball=sense.has_ball, role=self.role,
        )

    # -------------------------------------------------------------------- step
    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        self.view.update(tick, sense, order)
        self.order = order
        if order is None or sense is None or self.view.pose is None:
            return Cmd(tick=tick)
        if order.command != self.mem.command:
            self.mem.command, self.mem.command_since = order.command, tick
        self.role = order.role or self.role or "defender"
        if not self.view.has_ball:
            self.mem.carry_from = None
        elif self.mem.carry_from is None:
            self.mem.carry_from = (self.view.pose[0], self.view.pose[1])
            self.mem.hold_since = tick
        if order.command in SET_PIECES:
            return self.position_for_restart(tick, order)
        if order.command != PLAY:
            return Cmd(tick=tick)
        ball = self.view.ball
        if ball is None:
            return Cmd(tick=tick, omega=1.0)  # look round for the ball
        if self.keep_setpiece_distance(tick, order, ball):
            return self.position_for_restart(tick, order)
        if self.role == "goalkeeper":
            return self.goalkeeper(tick, order, ball)
        if self.view.has_ball:
            return self.with_ball(tick, order, ball)
        return self.without_ball(tick, order, ball)

    # ------------------------------------------------------------- geometry
    def goal(self, order: Order) -> Vec:
        return order.attack_dir * self.half_length, 0.0

    def own_goal(self, order: Order) -> Vec:
        return -order.attack_dir * self.half_length, 0.0

    def u(self, order: Order, x: float) -> float:
        return order.attack_dir * x

    def inside(self, pt: Vec, margin: float = 0.3) -> Vec:
        """pt clamped to the field plus `margin` [m] of run-off."""
        hx, hy = self.half_length + margin, self.half_width + margin
        return S.clamp(pt[0], -hx, hx), S.clamp(pt[1], -hy, hy)

    def my_area(self, order: Order) -> tuple[float, float]:
        roles = {n: r for n, (_, _, r) in self.view.mates.items() if n != 0 and r in ("attacker", "defender")}
        roles[self.n] = self.role
        return R.areas(roles, self.area_params).get(self.n, self.area_params.defense)

    # --------------------------------------------------------------- motion
    def drive(
        self, tick: int, target: Vec, heading: float, vmax: float, *, dribbler: bool = False, kick: float = 0.0,
        avoid: bool = True, extra_obstacles: tuple[Vec, ...] = (),
    ) -> Cmd:
        """Go to `target` [m] facing `heading` [rad] at most at vmax [m/s], steering round robots."""
        x, y, th = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        target = self.inside(target)
        d = S.dist(pos, target)
        if avoid and d > self.p.direct_range:
            obstacles = [o for o in self.view.others() if S.dist(o, pos) < self.p.obstacle_range]
            obstacles.extend(extra_obstacles)
            vx, vy = self.nav(pos, self.view.vel, target, obstacles, self.nav_params)
        else:
            vx, vy = (target[0] - x, target[1] - y)
        speed = math.hypot(vx, vy)
        cap = min(vmax, self.p.k_pos * d)
        if speed > cap and speed > 0.0:
            vx, vy = vx * cap / speed, vy * cap / speed
        vx, vy = self.guard_push(pos, vx, vy)
        omega, self.mem.pid = pid_step(self.mem.pid, heading, th, self.p.heading_pid)
        limit = self.p.dribble_omega if self.view.has_ball or dribbler and d < 0.6 else self.p.max_omega
        omega = S.clamp(omega, -limit, limit)
        c, s = math.cos(th), math.sin(th)
        return Cmd(tick=tick, vx=c * vx + s * vy, vy=-s * vx + c * vy, omega=omega, dribbler=dribbler, kick_speed=kick)

    def guard_push(self, pos: Vec, vx: float, vy: float) -> Vec:
        """Cap the closing speed towards every opponent within push_guard_range (no pushing fouls)."""
        for o in self.view.opponents:
            d = S.dist(pos, o)
            if 1e-6 < d < self.p.push_guard_range:
                ex, ey = (o[0] - pos[0]) / d, (o[1] - pos[1]) / d
                closing = vx * ex + vy * ey
                if closing > self.p.push_guard:
                    vx -= (closing - self.p.push_guard) * ex
                    vy -= (closing - self.p.push_guard) * ey
        return vx, vy

    def get_ball(self, tick: int, ball: Vec, target: Vec) -> Cmd:
        """Catch the ball so that it can then be pushed towards `target`."""
        sp = self.p.skills
        x, y, th = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        to_ball = S.angle_to(pos, ball)
        d = S.dist(pos, ball)
        if d < sp.behind_ball + 0.3 and (
            S.lined_up(pos, ball, target, sp.capture_lane) or abs(S.wrap(to_ball - th)) < 0.35
        ):
            return self.drive(tick, ball, to_ball, self.p.approach_speed, dribbler=True, avoid=False)
        behind = self.inside(S.behind_point(ball, target, sp.behind_ball), margin=0.1)
        heading = S.angle_to(ball, target) if S.dist(pos, behind) < 1.0 else to_ball
        return self.drive(tick, behind, heading, self.p.cruise, dribbler=d < 1.0, extra_obstacles=(ball,))

    def turn_and_kick(self, tick: int, aim: Vec, speed: float) -> Cmd:
        """Holding the ball: turn towards aim (slowly) and kick once facing it."""
        x, y, th = self.view.pose  # type: ignore[misc]
        want = S.angle_to((x, y), aim)
        kick = speed if abs(S.wrap(want - th)) < self.p.aim_tolerance else 0.0
        return self.drive(tick, (x, y), want, 0.0, dribbler=True, kick=kick, avoid=False)

    # ---------------------------------------------------------------- referee
    def position_for_restart(self, tick: int, order: Order) -> Cmd:
        spot = (order.spot_x, order.spot_y)
        goal = self.goal(order)
        x, y, _ = self.view.pose  # type: ignore[misc]
        if self.role == "goalkeeper":
            own = self.own_goal(order)
            target = (own[0] + order.attack_dir * self.p.skills.keeper_depth, 0.0)
            return self.drive(tick, target, S.angle_to(target, spot), self.p.cruise)
        ours = order.command_team in (self.team, "")
        if ours and self.is_taker(order, spot):
            behind = order.command_team == self.team and order.command == "DROP_BALL"
            gap = self.p.setpiece_behind if order.command_team == self.team or behind else 1.0
            target = S.behind_point(spot, goal, gap)
            return self.drive(tick, target, S.angle_to(target, goal), self.p.cruise, extra_obstacles=(spot,))
        home = self.home(order, spot)
        keep = self.p.setpiece_distance + 0.2 if order.command_team != self.team else 1.2
        if S.dist(home, spot) < keep:
            a = S.angle_to(spot, home) if S.dist(home, spot) > 1e-6 else S.angle_to(spot, self.own_goal(order))
            home = self.inside((spot[0] + keep * math.cos(a), spot[1] + keep * math.sin(a)), margin=-0.2)
        return self.drive(tick, home, S.angle_to(home, spot), self.p.cruise, extra_obstacles=(spot,))

    def is_taker(self, order: Order, spot: Vec) -> bool:
        """The outfield robot of ours nearest the spot takes the set piece (robot number breaks ties)."""
        x, y, _ = self.view.pose  # type: ignore[misc]
        mine = (S.dist((x, y), spot), self.n)
        for n, (mx, my, _) in self.view.mates.items():
            if n != 0 and (S.dist((mx, my), spot), n) < mine:
                return False
        return True

    def keep_setpiece_distance(self, tick: int, order: Order, ball: Vec) -> bool:
        """After the opponents' set-piece START: stay away until the ball has moved or 2 s passed."""
        if order.command_team in (self.team, "") or self.role == "goalkeeper":
            return False
        fresh = tick - self.mem.command_since < int(2.0 / self.cfg.timing.dt)
        return fresh and S.dist(ball, (order.spot_x, order.spot_y)) < 0.3

    # ------------------------------------------------------------- positions
    def home(self, order: Order, ball: Vec) -> Vec:
        lo, hi = self.my_area(order)
        d = order.attack_dir
        bu = d * ball[0]
        if self.role == "attacker":
            shift = -1.0 if order.strategy == R.S_DEFENSIVE else 0.0
            u = S.clamp(bu + 1.5 + shift, lo + 0.5, hi - 1.5)
            yy = S.clamp(-0.5 * ball[1] + (1.0 if ball[1] <= 0 else -1.0), -2.5, 2.5)
            return d * u, yy
        shift = 1.0 if order.strategy == R.S_OFFENSIVE else 0.0
        own = self.own_goal(order)
        r = min(3.2 + shift, 0.5 * S.dist(own, ball) + 1.0)
        a = S.angle_to(own, ball)
        hx, hy = own[0] + r * math.cos(a), own[1] + r * math.sin(a)
        u = S.clamp(d * hx, lo + 1.0, hi - 0.3)
        return d * u, hy

    def is_chaser(self, order: Order, ball: Vec) -> bool:
        """Nearest to the ball among our outfield robots whose area holds it."""
        bu = self.u(order, ball[0])
        lo, hi = self.my_area(order)
        if not lo - 0.3 <= bu <= hi + 0.3:
            self.mem.chasing = False
            return False
        x, y, _ = self.view.pose  # type: ignore[misc]
        mine = S.dist((x, y), ball) - (self.p.chase_hysteresis if self.mem.chasing else 0.0)
        roles = {n: r for n, (_, _, r) in self.view.mates.items() if n != 0 and r in ("attacker", "defender")}
        roles[self.n] = self.role
        area = R.areas(roles, self.area_params)
        for n, (mx, my, _) in self.view.mates.items():
            if n == 0 or n not in area:
                continue
            mlo, mhi = area[n]
            if mlo - 0.3 <= bu <= mhi + 0.3 and (S.dist((mx, my), ball), n) < (mine, self.n):
                self.mem.chasing = False
                return False
        self.mem.chasing = True
        return True

    # ------------------------------------------------------------ behaviours
    def goalkeeper(self, tick: int, order: Order, ball: Vec) -> Cmd:
        own = self.own_goal(order)
        x, y, _ = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        if self.view.has_ball:
            return self.clear(tick, order, ball)
        near_goal = abs(ball[0] - own[0]) < self.cfg.field.penalty_area_depth and abs(ball[1]) < self.cfg.field.penalty_area_width / 2
        slow = math.hypot(*self.view.ball_vel) < 1.0
        opp = min((S.dist(o, ball) for o in self.view.opponents), default=math.inf)
        if near_goal and slow and S.dist(pos, ball) < min(1.5, opp):
            return self.get_ball(tick, ball, self.goal(order))
        target, _ = S.keeper_target(ball, self.view.ball_vel, own[0], self.goal_half, self.p.skills)
        return self.drive(tick, target, S.angle_to(pos, ball), self.p.cruise, dribbler=S.dist(pos, ball) < 1.0, avoid=False)

    def clear(self, tick: int, order: Order, ball: Vec) -> Cmd:
        """Goalkeeper or cornered defender with the ball: pass to a free teammate, else kick upfield."""
        x, y, _ = self.view.pose  # type: ignore[misc]
        target = self.pass_target(order)
        if target is not None:
            return self.turn_and_kick(tick, target, self.pass_speed(target))
        goal = self.goal(order)
        aim = (goal[0], S.clamp(y, -2.0, 2.0))
        return self.turn_and_kick(tick, aim, self.p.kick_speed)

    def pass_target(self, order: Order) -> Vec | None:
        """An attacker ahead of us with a clear line, if any."""
        x, y, _ = self.view.pose  # type: ignore[misc]
        best: Vec | None = None
        for n, (mx, my, role) in sorted(self.view.mates.items()):
            if n == 0 or role != "attacker":
                continue
            ahead = self.u(order, mx) - self.u(order, x)
            if ahead > 1.0 and S.line_clear((x, y), (mx, my), self.view.opponents, self.p.skills.clear_margin):
                best = (mx, my)
                break
        return best

    def pass_speed(self, target: Vec) -> float:
        x, y, _ = self.view.pose  # type: ignore[misc]
        return S.pass_speed(S.dist((x, y), target), self.p.pass_arrive, self.cfg.ball.rolling_decel, self.p.kick_speed)

    def with_ball(self, tick: int, order: Order, ball: Vec) -> Cmd:
        x, y, th = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        goal = self.goal(order)
        lo, hi = self.my_area(order)
        u = self.u(order, x)
        d_goal = S.dist(pos, goal)
        opponents = self.view.opponents
        carried = S.dist(pos, self.mem.carry_from) if self.mem.carry_from is not None else 0.0
        at_limit = carried > self.p.carry_limit
        held_long = (tick - self.mem.hold_since) * self.cfg.timing.dt > self.p.max_hold
        if self.p.advance:
            if self.role == "defender":
                target = self.pass_target(order)
                if target is not None:
                    return self.turn_and_kick(tick, target, self.pass_speed(target))
            aim, clear = S.best_aim(pos, goal[0], self.goal_half, opponents, self.p.skills.clear_margin)
            if (d_goal < self.p.advance_shoot_distance and clear) or d_goal < self.p.close_shot:
                return self.turn_and_kick(tick, aim, self.p.kick_speed)
            if u > hi - 0.3:  # static defender at the edge of its area
                return self.clear(tick, order, ball)
            if at_limit or held_long:
                target = self.pass_target(order)
                if target is not None:
                    return self.turn_and_kick(tick, target, self.pass_speed(target))
                if clear and d_goal < 2.0 * self.p.advance_shoot_distance:
                    return self.turn_and_kick(tick, aim, self.p.kick_speed)
                return self.turn_and_kick(tick, self.nudge_point(pos, goal, opponents), self.p.nudge_speed)
            blocker = S.blocker_ahead(pos, goal, opponents, self.p.skills.path_corridor, self.p.skills.path_lookahead)
            if blocker is not None:
                side = S.sidestep_target(pos, blocker, goal, self.p.skills.sidestep)
                back_to_it = S.angle_to(blocker, pos)
                return self.drive(tick, side, back_to_it, self.p.dribble_speed, dribbler=True, avoid=False)
            ahead = (goal[0] - order.attack_dir * min(self.p.advance_shoot_distance - 0.5, d_goal), aim[1] * 0.5)
            return self.drive(tick, ahead, S.angle_to(pos, aim), self.p.dribble_speed, dribbler=True, avoid=False)
        aim = (goal[0], self.open_side(goal[0]))
        if d_goal < self.p.basic_shoot_distance or u > hi - 0.3 or at_limit:
            return self.turn_and_kick(tick, aim, self.p.kick_speed)
        return self.drive(tick, goal, S.angle_to(pos, goal), self.p.dribble_speed, dribbler=True, avoid=False)

    def nudge_point(self, pos: Vec, goal: Vec, opponents: list[Vec]) -> Vec:
        """Where to push the ball ahead at the carry limit: goal-ward, turned away from the nearest opponent."""
        a = S.angle_to(pos, goal)
        near = min(opponents, key=lambda o: S.dist(o, pos), default=None)
        if near is not None and S.dist(near, pos) < 2.0:
            off = S.wrap(S.angle_to(pos, near) - a)
            a -= math.copysign(0.6, off) if abs(off) < 1.2 else 0.0
        return pos[0] + 2.0 * math.cos(a), pos[1] + 2.0 * math.sin(a)

    def open_side(self, goal_x: float) -> float:
        """Basic aim: 0.6 of the goal half-width on the side away from the keeper."""
        keeper_y, best = 0.0, 1.5  # [m] only a robot this close to the goal centre counts as the keeper
        for ox, oy in self.view.opponents:
            dd = math.hypot(ox - goal_x, oy)
            if dd < best:
                best, keeper_y = dd, oy
        return -0.6 * self.goal_half if keeper_y > 0 else 0.6 * self.goal_half

    def carrier(self, ball: Vec) -> Vec | None:
        near = [(S.dist(o, ball), o) for o in self.view.opponents]
        if not near:
            return None
        dd, o = min(near)
        return o if dd < self.p.possession_radius + 0.1 else None

    def without_ball(self, tick: int, order: Order, ball: Vec) -> Cmd:
        x, y, _ = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        goal = self.goal(order)
        attacking = R.is_attacking(order.role_state)
        mate_has_it = attacking and any(S.dist((mx, my), ball) < 0.4 for mx, my, _ in self.view.mates.values())
        if mate_has_it:
            home = self.home(order, ball)
            return self.drive(tick, home, S.angle_to(home, ball), self.p.cruise)
        if self.p.advance and self.role == "defender" and not attacking:
            carrier = self.carrier(ball)
            if carrier is not None and S.dist(pos, ball) > self.p.skills.take_distance and self.is_chaser(order, ball):
                block = S.block_point(carrier, self.own_goal(order), self.p.skills)
                return self.drive(tick, block, S.angle_to(block, carrier), self.p.cruise, dribbler=True)
        if self.is_chaser(order, ball):
            return self.get_ball(tick, ball, goal)
        home = self.home(order, ball)
        return self.drive(tick, home, S.angle_to(home, ball), self.p.cruise)


def _make(name: str, alias: str, advance: bool, dynamic: bool) -> Strategy:
    params = IrisParams(advance=advance, dynamic=dynamic)
    kind = ("advance" if advance else "basic") + " attack and defense, " + ("dynamic" if dynamic else "static") + " roles"
    return Strategy(
        name=name,
        make_team=lambda ctx: IrisTeam(ctx, params),
        make_robot=lambda ctx: IrisRobot(ctx, params),
        aliases=(alias,),
        description=f"{kind} (paper 2)",
    )


STRATEGIES = [
    _make("basic-static", "BS", advance=False, dynamic=False),
    _make("basic-dynamic", "BD", advance=False, dynamic=True),
    _make("advance-static", "AS", advance=True, dynamic=False),
    _make("advance-dynamic", "AD", advance=True, dynamic=True),
]
