"""The IRIS team play of paper 2: basic/advance attack and defense x static/dynamic roles.

Four strategies, registered by name (:data:`STRATEGIES`): ``basic-static``
(BS), ``basic-dynamic`` (BD), ``advance-static`` (AS), ``advance-dynamic`` (AD).
All four share robot speed and kick speed (paper 2: "the speed of movement of
the robot and the kick on goal is made the same for all the algorithms"), the
goalkeeper, the ball handling and the referee handling; they differ only in
what the paper makes them differ in: the attack and the defense of the outfield
robots (basic or advance, Fig. 7) and the role assignment (static or dynamic,
Fig. 6).

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
* goalkeeper (robot 0, all four strategies): guards the mouth and intercepts
  the predicted ball path (:func:`.skills.keeper_target`), clears balls that
  stop near it;
* outfield robots, per role and team mode (the Fig. 6 state in the order):
  - the ball: the robot whose area holds the ball and that is nearest goes
    for it (paper 2: "pick up the ball"); the others take their positions
    (`home`); a robot that has just passed leaves the ball to the receiver;
  - basic attack (paper 2, "Basic strategy algorithm"): the holder dribbles
    straight towards the goal and kicks from `basic_shoot_distance`, whatever
    stands in the way, at the side of the goal the keeper leaves open; a
    static defender at the edge of its area kicks the ball on to its attacker
    (a pass ahead of it, `pass_lead`), blocked line or not;
  - advance attack (Fig. 7a): shoot within `advance_shoot_distance` only when
    the line to the goal is clear (`.skills.best_aim`, the clear aim point
    needing the least turn), and carry a decided shot through for
    `shot_commit`; pass to a teammate that has a clear shot; a defender feeds
    the attacker when the pass line is clear; with an opponent in the path,
    go round it in a circle with the body between it and the ball, on the side
    away from the near touch line (`.skills.circle_past`, eq. 1 motion), then
    goal-ward again; closed down (`pressure_range`), pass if it can; at the
    carry limit, pass or push the ball ahead; never a shot from beyond
    `advance_shoot_distance` (paper 2: "shoot when within shooting distance
    and the line to the goal is clear"); the attacker without the ball
    gets open for a pass and a shot (`.skills.open_point`);
  - basic defense: the robot whose area holds the ball tries to catch it and
    grab it from the opponent (`get_ball`), the others wait at home;
  - advance defense (Fig. 7b): the outfield robot that gets onto the kick line
    soonest (`is_blocker`) meets an opponent carrying the ball within
    `block_zone` of our goal on its estimated kick line (the ball's line to our
    goal centre), 1 m from it, retreating with it down to 3 m from our goal
    centre and then following the ball (`.skills.block_point`), tracking the
    line at `block_gain`, and takes the ball within 0.5 m from the kick line;
    the other marks the opponent nearest our goal goal-side when it is within
    `mark_zone` of our goal (man-to-man marking, the paper's stated approach;
    the attacker only while the ball is within `drop_back` of our goal); at
    the opponents' free kicks, throw-ins, corners and kick-offs one robot
    walls the kick line 2.2 m from the spot and the other marks
    (`setpiece_defense`).
* ball handling, the same for all four strategies: the MSL dribbling limit (a
  holder releases the ball before `carry_limit` of straight carry: pass, shot,
  or a push ahead that it catches again, `nudge_point`); a robot that loses
  the ball to a tackle steps off it for `regroup` (basic: aside; advance:
  goal-side, back onto the kick line) instead of wrestling for it; a holder
  pinned for `stall_hold` plays the ball on (`unstall`).
* every motion goes through a navigator of :mod:`arena.navigation` (F-SFM by
  default, paper 1 eq. 3-14) with the robots within `obstacle_range` as
  obstacles, so that robots steer round each other; the heading uses the PID
  of paper 1 eq. 15-16 (:mod:`arena.navigation.pid`), capped below the
  dribbler's 3 rad/s while holding the ball. The closing speed towards an
  opponent, of the robot and of a ball it holds, is capped to what the drive
  can brake to `push_guard` before contact, and to `contact_push` (0) in
  contact (`guard_push`): no pushing fouls, no shoving, no driving the ball
  into an opponent.

Cost: what depends only on the order (areas, roles, teammates) is worked out
once per order (`_Plan`, `support_point`), not once per tick; with no robot
within `obstacle_range` the navigator is not called (F-SFM then gives the
straight line at cruise speed). The per-tick path (`step`, `drive`, the
goalkeeper, the chaser) keeps its constants in attributes worked out in
`__init__` and inlines small helpers (`inside`, `S.dist`, `S.angle_to`, `min`);
each inlined expression does the very float operations of the helper it stands
for, so that matches replay bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import cos, hypot, sin

from arena.navigation import PARAMS, get
from arena.navigation.fsfm import FSFMParams
from arena.navigation.pid import PIDParams
from arena.navigation.pid import update as pid_update
from arena.navigation.sfm import SFMParams
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, Sense, TeamPose
from arena.strategies import roles as R
from arena.strategies import skills as S
from arena.strategies.base import RobotContext, Strategy, TeamContext
from arena.strategies.world import FusionParams, RobotView, TeamModel

Vec = tuple[float, float]

PLAY = "START"
SET_PIECES = frozenset({"KICKOFF", "FREEKICK", "GOALKICK", "THROWIN", "CORNER", "PENALTY", "DROP_BALL"})
WALL_PIECES = frozenset({"KICKOFF", "FREEKICK", "THROWIN", "CORNER"})  # advance defense: wall and mark at these


@dataclass(frozen=True)
class IrisParams:
    advance: bool = False  # advance attack and defense (Fig. 7) instead of the basic play
    dynamic: bool = False  # dynamic roles (Fig. 6 inputs a and d) instead of static ones
    navigator: str = "f-sfm"  # arena.navigation name
    cruise: float = 2.5  # [m/s] travel speed, same for all four strategies
    dribble_speed: float = 1.5  # [m/s] while holding the ball
    approach_speed: float = 1.8  # [m/s] final approach onto the ball
    kick_speed: float = 8.0  # [m/s] shot speed (the kicker's full power), same for all four strategies
    basic_shoot_distance: float = 5.0  # [m] basic: kick from this distance to the goal centre
    advance_shoot_distance: float = 4.5  # [m] advance: shoot within this distance if the line is clear
    close_shot: float = 1.8  # [m] advance: shoot anyway this close
    pass_arrive: float = 1.5  # [m/s] ball speed at the receiver
    dribble_omega: float = 2.4  # [rad/s] turn-rate cap with the ball (the dribbler loses it at 3)
    max_omega: float = 5.0  # [rad/s] turn-rate cap without the ball
    aim_tolerance: float = 0.08  # [rad] largest heading error at which a shot or pass is taken
    shot_spread: float = 0.15  # [m] ... and at most this much off the aim point where the ball gets there
    min_aim_tolerance: float = 0.025  # [rad] (noise floor: the heading is sensed with 0.01 rad sigma)
    pass_lead: float = 0.8  # [m] a pass goes this far ahead of the receiver, towards the goal
    pass_rest: float = 1.0  # [s] after a pass the passer leaves the ball to the receiver this long
    k_pos: float = 2.5  # [1/s] arrival slow-down: speed <= k_pos * distance
    direct_range: float = 0.7  # [m] closer than this to a target the robot drives straight at it
    # [m] robots farther than this are no obstacle: beyond 1.5 m the F-SFM social force
    # (paper 1 eq. 6, sigma 0.3 m, r_ij 0.5 m) is below 2 % of the goal force at cruise speed
    obstacle_range: float = 1.5
    setpiece_distance: float = 2.0  # [m] opponents keep this far from a set-piece spot
    setpiece_behind: float = 0.5  # [m] the taker stands this far behind the ball
    chase_hysteresis: float = 0.4  # [m] the current chaser counts this much nearer
    possession_radius: float = 0.4  # [m] an opponent this close to the ball has it
    max_hold: float = 2.5  # [s] advance: act (shoot, pass or push ahead) after holding the ball this long
    carry_limit: float = 2.0  # [m] release the ball before this straight-line carry (MSL dribble limit 3 m)
    nudge_speed: float = 1.6  # [m/s] kick the ball ahead to restart a carry at the limit
    regroup: float = 0.6  # [s] after losing the ball to a tackle, step back this long ...
    regroup_clear: float = 0.6  # [m] ... first backing straight off the ball to this far (centre to ball centre)
    regroup_distance: float = 0.9  # [m] ... to this far from the ball (basic: aside, advance: goal-side)
    cover_depth: float = -2.5  # [m] along the attack direction: the defender's place while the team attacks
    mark_zone: float = 6.5  # [m] advance defense: an opponent this close to our goal (about our half) is marked (was 5)
    block_zone: float = (
        6.5  # [m] advance defense: a carrier this close to our goal is blocked, not left to the attacker
    )
    # [1/s] advance defense: the blocker drives straight onto the kick line at this speed per metre off it
    # (the plain 1 m/s per metre lets a carrier turning or circling at 1.5 m/s open a post); higher gains
    # rush the carrier into pushing fouls and long shots
    block_gain: float = 3.0
    drop_back: float = 4.5  # [m] advance defense: with the ball this close to our goal the attacker marks too
    take_angle: float = 0.5  # [rad] advance defense: the blocker takes the ball only this close to the kick line
    behind_penalty: float = (
        1.5  # [m] advance defense: extra way to the kick line for a robot not goal-side of the carrier
    )
    wall_margin: float = 0.2  # [m] advance defense: the set-piece wall stands this far beyond the 2 m the rules ask
    wall_exit_turn: float = 1.0  # [rad] ... a robot inside the 2 m circle leaves it at most this far off straight away
    pressure_range: float = 1.2  # [m] advance attack: a blocker this close leaves no room to go round it
    keeper_zone: float = 1.2  # [m] advance attack: an opponent this close to the goal centre is the keeper, no blocker
    shot_commit: float = 0.6  # [s] advance attack: once a clear shot is seen, turn and take it within this time
    stall_hold: float = 4.0  # [s] a holder still holding after this long plays the ball on (`unstall`)
    unstall_speed: float = 3.0  # [m/s]
    push_guard: float = 0.5  # [m/s] closing speed at contact with an opponent (pushing fouls above 1.5 for both)
    brake: float = 1.2  # [m/s^2] deceleration the push guard counts on (the drive gives 2)
    push_guard_range: float = 2.5  # [m] opponents closer than this (centre to centre) get the cap
    ball_contact_range: float = 0.4  # [m] held ball's centre to an opponent's centre: touching or nearly
    separate_speed: float = 0.5  # [m/s] a robot turning with the ball edges away from an opponent in contact
    contact_range: float = (
        0.65  # [m] centre to centre: the footprints (0.45 m squares) may touch (corner to corner 0.64)
    )
    contact_push: float = 0.0  # [m/s] closing speed cap towards an opponent in contact
    heading_pid: PIDParams = PIDParams(k_p=6.0, k_i=0.0, k_d=2.0)  # paper 1 eq. 16 gains for 50 Hz
    skills: S.SkillParams = S.SkillParams()
    fusion: FusionParams = FusionParams()
    overlap: float = 1.0  # [m] defender/attacker areas overlap (paper 2)

    def nav_params(self):
        if self.navigator == "f-sfm":
            return FSFMParams(sfm=SFMParams(max_speed=self.cruise, robot_radius=0.5, sigma=0.3))
        defaults = PARAMS[self.navigator]()
        return type(defaults)(
            **{**{f: getattr(defaults, f) for f in defaults.__dataclass_fields__}, "max_speed": self.cruise}
        )


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
    passed_at: int = -(1 << 30)  # [tick] of its latest pass
    kicked_at: int = -(1 << 30)  # [tick] of its latest kick command
    lost_at: int = -(1 << 30)  # [tick] when it last lost the ball (not by its own kick)
    circle_rot: float = 0.0  # advance attack: the way round the opponent it is circling (+1 ccw, -1 cw)
    circle_tick: int = -(1 << 30)  # [tick] of the latest circling step
    shot_until: int = -(1 << 30)  # [tick] a decided shot is carried through until then
    shot_aim: Vec = (0.0, 0.0)  # [m]
    blocking: bool = False  # advance defense: this robot is the one blocking the carrier
    pid_integral: float = 0.0  # [rad] heading PID state (paper 1 eq. 16): the sum of errors ...
    pid_error: float | None = None  # [rad] ... and the latest error (None before the first step)


@dataclass(slots=True)
class _Plan:
    """What follows from one order alone: roles, areas, teammates (worked out once per order; never changed)."""

    role: str
    area: tuple[float, float]  # (u_min, u_max) [m] of this robot
    areas: dict[int, tuple[float, float]]  # of every outfield teammate with a role
    attackers: tuple[Vec, ...]  # positions [m] of the teammates that are attackers, by robot number
    mates: tuple[Vec, ...]  # positions [m] of the outfield teammates, by robot number
    attacking: bool  # Fig. 6: the team is in attacking mode


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
        self.plan: _Plan | None = None
        self._support: tuple[Order | None, Vec] | None = None
        self._planned: Order | None = None
        self._ticks_2s = int(2.0 / cfg.timing.dt)
        self.tick = 0
        self.ball_reach = cfg.robot.size / 2.0 + cfg.ball.radius  # [m] robot centre to a held ball's centre
        self._commit_ticks = int(round(p.shot_commit / cfg.timing.dt))
        # Constants of the per-tick path, worked out once.
        self._dt = cfg.timing.dt  # [s]
        self._defense_area = self.area_params.defense
        self._areas: dict[tuple, dict[int, tuple[float, float]]] = {}  # R.areas by the roles it was given
        self._drive_hx = self.half_length + 0.3  # [m] `inside` with its default margin, for `drive`
        self._drive_hy = self.half_width + 0.3  # [m]
        self._penalty_half_width = cfg.field.penalty_area_width / 2  # [m]
        self._near_ball = p.skills.behind_ball + 0.3  # [m] `get_ball`: final approach within this
        self._guard = (p.push_guard_range, 2.0 * p.brake, p.push_guard * p.push_guard, p.contact_push)

    # ------------------------------------------------------------------ report
    def report(self, tick: int, sense: Sense | None) -> Report:
        if sense is None:
            pose = self.view.pose or (0.0, 0.0, 0.0)
            return Report(tick=tick, robot=self.n, pose=Pose(x=pose[0], y=pose[1], theta=pose[2]), role=self.role)
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
        view = self.view
        view.update(tick, sense, order)
        self.order = order
        self.tick = tick
        if order is None or sense is None or view.pose is None:
            return Cmd(tick=tick)
        mem = self.mem
        command = order.command
        if command != mem.command:
            mem.command, mem.command_since = command, tick
        self.role = order.role or self.role or "defender"
        if order is not self._planned:
            self.plan = self.make_plan(order)
            self._planned = order
        has_ball = view.has_ball
        if not has_ball:
            if mem.carry_from is not None and tick - mem.kicked_at > 2:
                mem.lost_at = tick
            mem.carry_from = None
        elif mem.carry_from is None:
            mem.carry_from = (view.pose[0], view.pose[1])
            mem.hold_since = tick
        if command in SET_PIECES:
            return self.position_for_restart(tick, order)
        if command != PLAY:
            return Cmd(tick=tick)
        ball = view.ball
        if ball is None:
            return Cmd(tick=tick, omega=1.0)  # look round for the ball
        if self.keep_setpiece_distance(tick, order, ball):
            return self.position_for_restart(tick, order)
        if self.role == "goalkeeper":
            return self.goalkeeper(tick, order, ball)
        if has_ball:
            return self.with_ball(tick, order, ball)
        return self.without_ball(tick, order, ball)

    def make_plan(self, order: Order) -> _Plan:
        roles = {n: r for n, (_, _, r) in self.view.mates.items() if n != 0 and r in ("attacker", "defender")}
        if self.n != 0:
            roles[self.n] = self.role
        key = tuple(roles.items())  # the areas follow from the roles alone: worked out once per set of roles
        areas = self._areas.get(key)
        if areas is None:
            areas = self._areas[key] = R.areas(roles, self.area_params)
        attackers: list[Vec] = []
        mates: list[Vec] = []
        for n, (x, y, r) in sorted(self.view.mates.items()):
            if n != 0:
                mates.append((x, y))
                if r == "attacker":
                    attackers.append((x, y))
        return _Plan(
            role=self.role,
            area=areas.get(self.n, self._defense_area),
            areas=areas,
            attackers=tuple(attackers),
            mates=tuple(mates),
            attacking=R.is_attacking(order.role_state),
        )

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
        return self.plan.area  # type: ignore[union-attr]

    # --------------------------------------------------------------- motion
    def drive(
        self,
        tick: int,
        target: Vec,
        heading: float,
        vmax: float,
        *,
        dribbler: bool = False,
        kick: float = 0.0,
        avoid: bool = True,
        extra_obstacles: tuple[Vec, ...] = (),
        gain: float = 0.0,
    ) -> Cmd:
        """Go to `target` [m] facing `heading` [rad] at most at vmax [m/s], steering round robots;
        `gain` [1/s]: drive straight at speed min(vmax, gain * distance) (without it the straight
        speed is the distance per second, capped by `k_pos`)."""
        view, p = self.view, self.p
        x, y, th = view.pose  # type: ignore[misc]
        # target = self.inside(target), inlined
        gx, gy, hx, hy = target[0], target[1], self._drive_hx, self._drive_hy
        gx = -hx if gx < -hx else hx if gx > hx else gx
        gy = -hy if gy < -hy else hy if gy > hy else gy
        tx, ty = gx - x, gy - y
        d = hypot(tx, ty)
        vx, vy = tx, ty  # straight at it, at 1 m/s per metre to go (capped below)
        if gain and d > 1e-9:  # straight at it at gain * distance (a tracking robot: blocker, marker)
            k = gain * d
            k = (k if k < vmax else vmax) / d  # min(vmax, gain * d) / d
            vx, vy = tx * k, ty * k
        if avoid and d > p.direct_range:
            near = p.obstacle_range
            obstacles = []  # every other robot (view.others(): opponents, then teammates) and the extras within reach
            for group in (view.opponents, view.mate_obstacles, extra_obstacles):
                for o in group:
                    dx, dy = o[0] - x, o[1] - y
                    if -near < dx < near and -near < dy < near and hypot(dx, dy) < near:
                        obstacles.append(o)
            if obstacles:  # with none, F-SFM's answer is the straight line at cruise speed
                vx, vy = self.nav((x, y), view.vel, (gx, gy), obstacles, self.nav_params)
        speed = hypot(vx, vy)
        cap = (gain or p.k_pos) * d
        cap = cap if cap < vmax else vmax  # min(vmax, (gain or k_pos) * d)
        if speed > cap and speed > 0.0:
            vx, vy = vx * cap / speed, vy * cap / speed
        c, s = cos(th), sin(th)
        vx, vy = self.guard_push(x, y, vx, vy, p.contact_range)
        has_ball = view.has_ball
        if has_ball:  # the held ball is part of the body: do not push it into an opponent either
            reach = self.ball_reach
            vx, vy = self.guard_push(x + reach * c, y + reach * s, vx, vy, p.ball_contact_range)
        mem = self.mem
        omega, mem.pid_integral, mem.pid_error = pid_update(mem.pid_integral, mem.pid_error, heading, th, p.heading_pid)
        limit = p.dribble_omega if has_ball or dribbler and d < 0.6 else p.max_omega
        omega = -limit if omega < -limit else limit if omega > limit else omega
        return Cmd(tick=tick, vx=c * vx + s * vy, vy=-s * vx + c * vy, omega=omega, dribbler=dribbler, kick_speed=kick)

    def guard_push(self, x: float, y: float, vx: float, vy: float, contact: float) -> Vec:
        """Cap the closing speed towards every nearby opponent, so that contact is never a pushing foul.

        (x, y) is the point that must not push: the robot's centre (contact at
        `contact_range`) or the centre of the ball it holds (`ball_contact_range`).
        The cap is what the drive can still brake from before the bodies meet:
        v <= sqrt(push_guard^2 + 2 brake (d - contact)) at distance d [m], so
        that the robot arrives at `push_guard` or slower whatever its
        acceleration limit; in contact (d < contact) it is `contact_push`: a
        robot does not shove an opponent along (MSL: charging), so a carrier
        that shields the ball with its body can turn away, and a holder does
        not drive the ball into an opponent (which would knock it loose).
        """
        rng, brake2, guard2, contact_push = self._guard
        if vx == 0.0 and vy == 0.0 and contact_push >= 0.0:  # not moving: closing on nobody
            return vx, vy
        for ox, oy in self.view.opponents:
            dx, dy = ox - x, oy - y
            if abs(dx) > rng or abs(dy) > rng:
                continue
            d = hypot(dx, dy)
            if 1e-6 < d < rng:
                ex, ey = dx / d, dy / d
                closing = vx * ex + vy * ey
                if closing <= contact_push:
                    continue
                cap = contact_push if d < contact else math.sqrt(guard2 + brake2 * (d - contact))
                if closing > cap:
                    vx -= (closing - cap) * ex
                    vy -= (closing - cap) * ey
        return vx, vy

    def get_ball(self, tick: int, ball: Vec, target: Vec) -> Cmd:
        """Catch the ball so that it can then be pushed towards `target`."""
        p = self.p
        sp = p.skills
        x, y, th = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        bx, by = ball
        to_ball = math.atan2(by - y, bx - x)  # S.angle_to(pos, ball)
        d = hypot(x - bx, y - by)  # S.dist(pos, ball)
        if d < self._near_ball and (S.lined_up(pos, ball, target, sp.capture_lane) or abs(S.wrap(to_ball - th)) < 0.35):
            return self.drive(tick, ball, to_ball, p.approach_speed, dribbler=True, avoid=False)
        a = math.atan2(target[1] - by, target[0] - bx)  # S.angle_to(ball, target) ...
        off = sp.behind_ball  # ... for S.behind_point(ball, target, behind_ball)
        behind = self.inside((bx - off * cos(a), by - off * sin(a)), margin=0.1)
        heading = a if hypot(x - behind[0], y - behind[1]) < 1.0 else to_ball
        return self.drive(tick, behind, heading, p.cruise, dribbler=d < 1.0, extra_obstacles=(ball,))

    def turn_and_kick(self, tick: int, aim: Vec, speed: float, *, is_pass: bool = False) -> Cmd:
        """Holding the ball: turn towards aim (slowly) and kick once facing it.

        The kick is taken once the ball would pass within `shot_spread` of aim,
        i.e. at a heading error below atan(shot_spread / distance), between
        `min_aim_tolerance` and `aim_tolerance`; passes allow twice the spread.
        """
        x, y, th = self.view.pose  # type: ignore[misc]
        want = S.angle_to((x, y), aim)
        spread = self.p.shot_spread * (2.0 if is_pass else 1.0)
        tol = S.clamp(math.atan2(spread, S.dist((x, y), aim)), self.p.min_aim_tolerance, self.p.aim_tolerance)
        # The kick leaves along the heading of the next tick, when the command applies.
        kick = speed if abs(S.wrap(want - th - self.view.omega * self.cfg.timing.dt)) < tol else 0.0
        if kick:
            self.mem.kicked_at = tick
            if is_pass:
                self.mem.passed_at = tick
        # Turning on the spot; an opponent in contact would jam the turn, so edge away from it.
        spot = (x, y)
        near = self.nearest_opponent(x, y)
        if near is not None and S.dist(near, spot) < self.p.contact_range:
            a = S.angle_to(near, spot)
            spot = (x + 0.5 * math.cos(a), y + 0.5 * math.sin(a))
        return self.drive(
            tick, spot, want, self.p.separate_speed if spot != (x, y) else 0.0, dribbler=True, kick=kick, avoid=False
        )

    def nearest_opponent(self, x: float, y: float) -> Vec | None:
        best, found = math.inf, None
        for o in self.view.opponents:
            d = abs(o[0] - x) + abs(o[1] - y)
            if d < best:
                best, found = d, o
        return found

    def pass_to(self, tick: int, target: Vec) -> Cmd:
        return self.turn_and_kick(tick, target, self.pass_speed(target), is_pass=True)

    # ---------------------------------------------------------------- referee
    def position_for_restart(self, tick: int, order: Order) -> Cmd:
        spot = (order.spot_x, order.spot_y)
        goal = self.goal(order)
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
        if self.p.advance and order.command_team not in (self.team, "") and order.command in WALL_PIECES:
            target = self.setpiece_defense(order, spot)
            if target is not None:
                x, y, _ = self.view.pose  # type: ignore[misc]
                keep = self.p.setpiece_distance + self.p.wall_margin
                if S.dist((x, y), spot) < keep - 0.1:
                    # Inside the 2 m circle: out of it first, away from the spot but turned (by up to
                    # `wall_exit_turn`) towards the target, so that it leaves on the way round to it.
                    a = S.angle_to(spot, (x, y)) if S.dist((x, y), spot) > 1e-6 else S.angle_to(spot, target)
                    turn = S.wrap(S.angle_to(spot, target) - a)
                    a += S.clamp(turn, -self.p.wall_exit_turn, self.p.wall_exit_turn)
                    target = (spot[0] + keep * math.cos(a), spot[1] + keep * math.sin(a))
                return self.drive(tick, target, S.angle_to(target, spot), self.p.cruise, extra_obstacles=(spot,))
        home = self.home(order, spot)
        keep = self.p.setpiece_distance + 0.2 if order.command_team != self.team else 1.2
        if S.dist(home, spot) < keep:
            a = S.angle_to(spot, home) if S.dist(home, spot) > 1e-6 else S.angle_to(spot, self.own_goal(order))
            home = self.inside((spot[0] + keep * math.cos(a), spot[1] + keep * math.sin(a)), margin=-0.2)
        return self.drive(tick, home, S.angle_to(home, spot), self.p.cruise, extra_obstacles=(spot,))

    def setpiece_defense(self, order: Order, spot: Vec) -> Vec | None:
        """Advance defense at the opponents' set piece: Fig. 7b before the ball is in play.

        The outfield robot nearer the wall point stands on the kick line from
        the spot to our goal centre, `setpiece_distance` + `wall_margin` from
        the spot (the block of Fig. 7b at the distance the rules allow, never
        nearer our goal centre than `retreat_radius` less 1 m); the other marks the
        opponent nearest our goal other than the taker goal-side
        (`.skills.mark_point`), kept out of the 2 m circle too. None: no mark
        for it (it takes its usual place).
        """
        own = self.own_goal(order)
        keep = self.p.setpiece_distance + self.p.wall_margin
        d = S.dist(spot, own)
        r = max(min(self.p.skills.retreat_radius - 1.0, d), d - keep)
        a = S.angle_to(own, spot)
        wall = self.inside((own[0] + r * math.cos(a), own[1] + r * math.sin(a)), margin=-0.3)
        x, y, _ = self.view.pose  # type: ignore[misc]
        mine = (S.dist((x, y), wall), self.n)
        walls = all((S.dist((mx, my), wall), n) > mine for n, (mx, my, _) in self.view.mates.items() if n != 0)
        if walls:
            return wall
        best, found = self.p.mark_zone + 1.0, None
        for o in self.view.opponents:
            dd = S.dist(o, own)
            if S.dist(o, spot) > 1.0 and dd < best:
                best, found = dd, o
        if found is None:
            return None
        mark = S.mark_point(found, own, self.p.skills.mark_distance)
        if S.dist(mark, spot) < keep:
            b = S.angle_to(spot, mark)
            mark = (spot[0] + keep * math.cos(b), spot[1] + keep * math.sin(b))
        return self.inside(mark, margin=-0.3)

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
        fresh = tick - self.mem.command_since < self._ticks_2s
        return fresh and S.dist(ball, (order.spot_x, order.spot_y)) < 0.3

    # ------------------------------------------------------------- positions
    def home(self, order: Order, ball: Vec) -> Vec:
        """Where a robot waits while it does not go for the ball, by role and team mode.

        Attacker: in attacking mode up the field, on the other side from the
        ball, to receive the ball; in defending mode just ahead of the ball, in
        its area, ready for a counter-attack. Defender: in attacking mode at
        `cover_depth` in its own half, following the ball's y a little; in
        defending mode between the ball and our goal, at most 3.2 m out.
        S2 (losing) pushes everyone 1 m up, S3 (winning) 1 m back.
        """
        lo, hi = self.plan.area  # type: ignore[union-attr]
        d = order.attack_dir
        bu = d * ball[0]
        shift = 1.0 if order.strategy == R.S_OFFENSIVE else -1.0 if order.strategy == R.S_DEFENSIVE else 0.0
        attacking = self.plan.attacking  # type: ignore[union-attr]
        if self.role == "attacker":
            if attacking:
                u = S.clamp(bu + 2.5 + shift, max(lo + 1.5, 1.0), hi - 2.0)
                yy = -1.5 if ball[1] > 0.5 else 1.5 if ball[1] < -0.5 else (1.5 if self.n % 2 else -1.5)
                return d * u, yy
            u = S.clamp(bu + 1.5 + shift, lo + 0.5, hi - 1.5)
            yy = S.clamp(-0.5 * ball[1] + (1.0 if ball[1] <= 0 else -1.0), -2.5, 2.5)
            return d * u, yy
        if attacking:  # cover behind the play, little moved by the ball: the defender's area is its own half
            u = S.clamp(self.p.cover_depth + shift, lo + 1.5, hi - 0.3)
            return d * u, 0.25 * ball[1]
        own = self.own_goal(order)
        r = min(3.2 + max(shift, 0.0), 0.5 * S.dist(own, ball) + 1.0)
        a = S.angle_to(own, ball)
        hx, hy = own[0] + r * math.cos(a), own[1] + r * math.sin(a)
        u = S.clamp(d * hx, lo + 1.0, hi - 0.3)
        return d * u, hy

    def support_point(self, order: Order, ball: Vec) -> Vec:
        """Advance attack: get open for a pass and a shot (`.skills.open_point`), worked out once per order."""
        if self._support is not None and self._support[0] is self.order:
            return self._support[1]
        lo, hi = self.my_area(order)
        d = order.attack_dir
        bu = d * ball[0]
        us = {S.clamp(bu + k, max(lo + 1.0, 0.5), min(hi - 1.5, 4.5)) for k in (1.5, 3.0)}
        cands = [(d * u, yy) for u in sorted(us) for yy in (-1.5, 0.0, 1.5)]
        pt = S.open_point(
            ball, cands, self.view.opponents, self.goal(order)[0], self.goal_half, self.p.skills.clear_margin
        )
        self._support = (self.order, pt)
        return pt

    def is_chaser(self, order: Order, ball: Vec) -> bool:
        """Nearest to the ball among our outfield robots whose area holds it (a fresh passer leaves it)."""
        mem = self.mem
        bu = order.attack_dir * ball[0]  # self.u(order, ball[0])
        lo, hi = self.plan.area  # type: ignore[union-attr]
        if (self.tick - mem.passed_at) * self._dt < self.p.pass_rest:
            mem.chasing = False
            return False
        if not lo - 0.3 <= bu <= hi + 0.3:
            mem.chasing = False
            return False
        x, y, _ = self.view.pose  # type: ignore[misc]
        bx, by = ball
        mine = hypot(x - bx, y - by) - (self.p.chase_hysteresis if mem.chasing else 0.0)
        me = self.n
        area = self.plan.areas  # type: ignore[union-attr]
        for n, (mx, my, _) in self.view.mates.items():
            if n == 0 or n not in area:
                continue
            mlo, mhi = area[n]
            if mlo - 0.3 <= bu <= mhi + 0.3:
                dm = hypot(mx - bx, my - by)
                if dm < mine or dm == mine and n < me:  # (dm, n) < (mine, me)
                    mem.chasing = False
                    return False
        mem.chasing = True
        return True

    # ------------------------------------------------------------ behaviours
    def goalkeeper(self, tick: int, order: Order, ball: Vec) -> Cmd:
        view = self.view
        if view.has_ball:
            return self.clear(tick, order, ball)
        own_x = self.own_goal(order)[0]
        x, y, _ = view.pose  # type: ignore[misc]
        bx, by = ball
        d_ball = hypot(x - bx, y - by)  # S.dist(pos, ball)
        near_goal = abs(bx - own_x) < self.cfg.field.penalty_area_depth and abs(by) < self._penalty_half_width
        if near_goal and hypot(*view.ball_vel) < 1.0:  # near our goal and slow: the keeper may take it
            opp = math.inf  # the nearest opponent's distance to the ball
            for ox, oy in view.opponents:
                dd = hypot(ox - bx, oy - by)
                if dd < opp:
                    opp = dd
            if d_ball < (opp if opp < 1.5 else 1.5):  # min(1.5, opp)
                return self.get_ball(tick, ball, self.goal(order))
        target, _ = S.keeper_target(ball, view.ball_vel, own_x, self.goal_half, self.p.skills)
        return self.drive(tick, target, math.atan2(by - y, bx - x), self.p.cruise, dribbler=d_ball < 1.0, avoid=False)

    def clear(self, tick: int, order: Order, ball: Vec) -> Cmd:
        """Goalkeeper or cornered defender with the ball: pass to a free teammate, else kick upfield."""
        x, y, _ = self.view.pose  # type: ignore[misc]
        target = self.pass_target(order)
        if target is not None:
            return self.pass_to(tick, target)
        goal = self.goal(order)
        aim = (goal[0], S.clamp(y, -2.0, 2.0))
        return self.turn_and_kick(tick, aim, self.p.kick_speed)

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
        goal = self.goal(order)
        a = S.angle_to(mate, goal)
        return self.inside((mate[0] + self.p.pass_lead * math.cos(a), mate[1] + self.p.pass_lead * math.sin(a)), -0.5)

    def feed_target(self, order: Order) -> Vec | None:
        """Basic: an attacker ahead of us, clear line or not."""
        x, _, _ = self.view.pose  # type: ignore[misc]
        for mx, my in self.plan.attackers:  # type: ignore[union-attr]
            if self.u(order, mx) - self.u(order, x) > 0.5:
                return self.lead_point(order, (mx, my))
        return None

    def pass_speed(self, target: Vec) -> float:
        x, y, _ = self.view.pose  # type: ignore[misc]
        return S.pass_speed(S.dist((x, y), target), self.p.pass_arrive, self.cfg.ball.rolling_decel, self.p.kick_speed)

    def with_ball(self, tick: int, order: Order, ball: Vec) -> Cmd:
        x, y, _ = self.view.pose  # type: ignore[misc]
        pos = (x, y)
        goal = self.goal(order)
        carried = S.dist(pos, self.mem.carry_from) if self.mem.carry_from is not None else 0.0
        at_limit = carried > self.p.carry_limit
        if (tick - self.mem.hold_since) * self.cfg.timing.dt > self.p.stall_hold:
            return self.unstall(tick, order)
        if self.p.advance:
            return self.advance_attack(tick, order, ball, pos, goal, at_limit)
        return self.basic_attack(tick, order, ball, pos, goal, at_limit)

    def basic_attack(self, tick: int, order: Order, ball: Vec, pos: Vec, goal: Vec, at_limit: bool) -> Cmd:
        """Paper 2, basic strategy: dribble towards the goal, kick from a set distance."""
        aim = (goal[0], self.open_side(goal[0]))
        if S.dist(pos, goal) < self.p.basic_shoot_distance:
            return self.turn_and_kick(tick, aim, self.p.kick_speed)
        _, hi = self.my_area(order)
        if not self.p.dynamic and self.u(order, pos[0]) > hi - 0.3:
            # A static robot may not leave its area: kick the ball on to the attacker, else at the goal.
            target = self.feed_target(order)
            if target is not None:
                return self.pass_to(tick, target)
            return self.turn_and_kick(tick, aim, self.p.kick_speed)
        if at_limit:
            return self.turn_and_kick(tick, self.nudge_point(pos, goal, []), self.p.nudge_speed)
        return self.drive(tick, goal, S.angle_to(pos, goal), self.p.dribble_speed, dribbler=True, avoid=False)

    def advance_attack(self, tick: int, order: Order, ball: Vec, pos: Vec, goal: Vec, at_limit: bool) -> Cmd:
        """Paper 2, Fig. 7a: feed the attacker, sidestep blockers with the back to them, shoot when clear."""
        opponents = self.view.opponents
        d_goal = S.dist(pos, goal)
        sp = self.p.skills
        if tick <= self.mem.shot_until:  # a shot once decided is carried through (the line may flicker)
            return self.turn_and_kick(tick, self.mem.shot_aim, self.p.kick_speed)
        heading = self.view.pose[2]  # type: ignore[index]
        aim, clear = S.best_aim(pos, goal[0], self.goal_half, opponents, sp.clear_margin, heading=heading)
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
        field_players = [o for o in opponents if S.dist(o, goal) > self.p.keeper_zone]  # the keeper is no blocker
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
        ahead = (goal[0] - order.attack_dir * min(self.p.advance_shoot_distance - 0.5, d_goal), aim[1] * 0.5)
        return self.drive(tick, ahead, S.angle_to(pos, aim), self.p.dribble_speed, dribbler=True, avoid=False)

    def unstall(self, tick: int, order: Order) -> Cmd:
        """Held the ball too long (pinned against an opponent): play it on along the heading,
        unless that points towards our goal."""
        x, y, th = self.view.pose  # type: ignore[misc]
        if math.cos(th) * order.attack_dir > -0.3:
            self.mem.kicked_at = tick
            return self.drive(tick, (x, y), th, 0.0, dribbler=True, kick=self.p.unstall_speed, avoid=False)
        return self.turn_and_kick(tick, self.goal(order), self.p.unstall_speed)

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
        """The opponent nearest the ball if it is close enough to have it (min of (distance, position))."""
        bx, by = ball
        best_d, best = math.inf, None
        for o in self.view.opponents:
            dd = hypot(o[0] - bx, o[1] - by)  # S.dist(o, ball)
            if best is None or dd < best_d or dd == best_d and o < best:
                best_d, best = dd, o
        if best is None:
            return None
        return best if best_d < self.p.possession_radius + 0.1 else None

    def without_ball(self, tick: int, order: Order, ball: Vec) -> Cmd:
        view, p = self.view, self.p
        x, y, _ = view.pose  # type: ignore[misc]
        pos = (x, y)
        goal = self.goal(order)
        if (tick - self.mem.lost_at) * self._dt < p.regroup and self.carrier(ball) is not None:
            # Lost the ball to a tackle: step back instead of wrestling for it, then challenge again;
            # basic: aside; advance: goal-side, onto the carrier's kick line (Fig. 7b).
            if S.dist(pos, ball) < self.p.regroup_clear:  # first get the body off the ball, straight back
                a = S.angle_to(ball, pos)
                back = (x + 0.5 * math.cos(a), y + 0.5 * math.sin(a))
            elif self.p.advance:
                back = S.behind_point(ball, goal, self.p.regroup_distance)
            else:
                back = S.aside_point(ball, self.own_goal(order), pos, self.p.regroup_distance)
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
                    return self.drive(tick, home, S.angle_to(home, ball), p.cruise)
        chaser = self.is_chaser(order, ball)
        if p.advance and not attacking:
            cmd = self.advance_defense(tick, order, ball, pos, chaser)
            if cmd is not None:
                return cmd
        if chaser:
            return self.get_ball(tick, ball, goal)
        home = self.home(order, ball)
        return self.drive(tick, home, S.angle_to(home, ball), p.cruise)

    def advance_defense(self, tick: int, order: Order, ball: Vec, pos: Vec, chaser: bool) -> Cmd | None:
        """Paper 2, Fig. 7b, for an outfield robot while the team defends; None: play the ball as usual.

        An opponent carrying the ball within `block_zone` of our goal is met by
        the robot that gets onto its kick line soonest (`is_blocker`) on that
        line (the ball's line to our goal centre), `block_distance` (1 m) from
        the carrier and no closer than `retreat_radius` (3 m) to our goal
        centre, facing the ball (`.skills.block_point`); within
        `take_distance` (0.5 m) of the ball it takes it, straight from the kick
        line (within `take_angle` of it). It drives there straight once goal-side of the carrier
        (steering round it only to get goal-side) and with the tracking gain
        `block_gain`, so that it stays on the line while the carrier turns to
        aim or circles. The other outfield robot marks the most dangerous
        other opponent goal-side (man-to-man marking, `.skills.mark_point`),
        which also cuts the pass to it: the defender always, the attacker while
        the ball is within `drop_back` of our goal (both field robots defend
        when the team has lost the ball deep in its half; paper 2: "defender
        robots ... will always block opposing attacker to score goal").
        """
        sp = self.p.skills
        own = self.own_goal(order)
        carrier = self.carrier(ball)
        if carrier is not None and S.dist(carrier, own) < self.p.block_zone:
            block = S.block_point(carrier, own, sp, ball)
            if self.is_blocker(block, carrier, own):
                # Within take_distance of the ball, take it, but only from the kick line: straight at the
                # ball from goal-side; going round the ball to get behind it would open the line to our goal.
                on_line = abs(S.wrap(S.angle_to(ball, pos) - S.angle_to(ball, own))) < self.p.take_angle
                if S.dist(pos, ball) < sp.take_distance and on_line:
                    return self.drive(
                        tick, ball, S.angle_to(pos, ball), self.p.approach_speed, dribbler=True, avoid=False
                    )
                goal_side = S.dist(pos, own) < S.dist(carrier, own) - 0.2
                return self.drive(
                    tick,
                    block,
                    S.angle_to(block, ball),
                    self.p.cruise,
                    dribbler=True,
                    avoid=not goal_side,
                    gain=self.p.block_gain,
                )
        else:
            self.mem.blocking = False
            if chaser:
                return None
        if self.role == "attacker" and S.dist(ball, own) > self.p.drop_back:
            return None
        target = self.marking_target(order, carrier if carrier is not None else ball)
        if target is None:
            return None
        mark = S.mark_point(target, own, sp.mark_distance)
        return self.drive(tick, mark, S.angle_to(mark, ball), self.p.cruise)

    def is_blocker(self, block: Vec, carrier: Vec, own: Vec) -> bool:
        """Advance defense: of our outfield robots, the one that gets onto the kick line soonest blocks:
        the nearest to the block point, counting `behind_penalty` more for a robot not goal-side of the
        carrier (it has to go round it) and `chase_hysteresis` less for the current blocker."""
        limit = S.dist(carrier, own) - 0.2

        def cost(pt: Vec) -> float:
            return S.dist(pt, block) + (self.p.behind_penalty if S.dist(pt, own) > limit else 0.0)

        x, y, _ = self.view.pose  # type: ignore[misc]
        mine = (cost((x, y)) - (self.p.chase_hysteresis if self.mem.blocking else 0.0), self.n)
        self.mem.blocking = all((cost((mx, my)), n) > mine for n, (mx, my, _) in self.view.mates.items() if n != 0)
        return self.mem.blocking

    def marking_target(self, order: Order, carrier: Vec) -> Vec | None:
        """The opponent other than the carrier nearest our goal, if it is within `mark_zone` of it."""
        own = self.own_goal(order)
        best, found = self.p.mark_zone, None
        for o in self.view.opponents:
            if S.dist(o, carrier) < 0.3:
                continue
            d = S.dist(o, own)
            if d < best:
                best, found = d, o
        return found


def _make(name: str, alias: str, advance: bool, dynamic: bool) -> Strategy:
    params = IrisParams(advance=advance, dynamic=dynamic)
    kind = (
        ("advance" if advance else "basic") + " attack and defense, " + ("dynamic" if dynamic else "static") + " roles"
    )
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
