"""The IRIS robot brain: memory, the plan of an order, and the step that picks a behaviour.

Robot (`IrisRobot`), every tick, from its own `Sense` and the latest `Order`
(:class:`arena.strategies.world.RobotView`; robots never see ground truth): the
referee first (setpieces.py), then the goalkeeper (keeper.py), then the
outfield robot with the ball (handling.py, attack.py) or without it
(defense.py, positions.py).
"""

from __future__ import annotations

from arena.navigation import get
from arena.schemas.messages import Cmd, Order, Report, Sense
from arena.schemas.vocabulary import SET_PIECES
from arena.strategies import roles as R
from arena.strategies.base import RobotContext, report_of
from arena.strategies.iris.attack import AttackMixin
from arena.strategies.iris.defense import DefenseMixin
from arena.strategies.iris.handling import HandlingMixin
from arena.strategies.iris.keeper import KeeperMixin
from arena.strategies.iris.memory import Memory, Plan
from arena.strategies.iris.motion import MotionMixin
from arena.strategies.iris.params import PLAY, IrisParams, Vec
from arena.strategies.iris.positions import PositionsMixin
from arena.strategies.iris.setpieces import SetPieceMixin
from arena.strategies.world import RobotView

_ATTACKING = (R.ATTACKING_ATTACKER, R.ATTACKING_DEFENDER)  # `R.is_attacking`: the states of attacking mode


class IrisRobot(MotionMixin, HandlingMixin, AttackMixin, DefenseMixin, KeeperMixin, SetPieceMixin, PositionsMixin):
    """Robot brain: perception, skills and the referee, for every role."""

    # Slots: the brain reads these attributes and calls its own methods many times a tick. An instance dict
    # past 29 keys is no longer shared (CPython 3.11), and every `self.method()` then costs ~250 more
    # instructions; "__dict__" keeps room for attributes a test or a wrapper adds.
    __slots__ = (
        *("cfg", "team", "n", "p", "half_length", "half_width", "goal_half", "view", "nav", "nav_params"),
        *("area_params", "mem", "role", "order", "plan", "_support", "_restart", "_planned", "_keep_away_until"),
        *("_ticks_2s", "tick", "ball_reach", "_commit_ticks", "_dt", "_defense_area", "_areas", "_drive_hx"),
        *("_drive_hy", "_penalty_half_width", "_near_ball", "_pid", "_guard", "_guard_shrinks", "_static_area"),
        "_guard_body",
        "__dict__",
    )

    def __init__(self, ctx: RobotContext, p: IrisParams):
        cfg = ctx.cfg
        self.cfg = cfg
        self.team = ctx.team
        self.n = ctx.n
        self.p = p
        self.half_length = cfg.field.length / 2.0
        self.half_width = cfg.field.width / 2.0
        self.goal_half = cfg.field.goal_width / 2.0
        self.view = RobotView(ctx.team, ctx.n, cfg.sensor, cfg.timing.dt, p.fusion, cfg.timing.perception_latency)
        self.nav = get(p.navigator)
        self.nav_params = p.nav_params()
        self.area_params = R.AreaParams(field_length=cfg.field.length, overlap=p.overlap)
        self.mem = Memory()
        self.role = "goalkeeper" if ctx.n == 0 else ""
        self.order: Order | None = None
        self.plan: Plan | None = None
        self._support: tuple[Order | None, Vec] | None = None
        self._restart: tuple[Order, Vec, float, tuple[Vec, ...]] | None = None  # see `position_for_restart`
        self._planned: Order | None = None
        self._keep_away_until = -1  # [tick] see `step`
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
        pid = p.heading_pid
        # `_heading_pid`: the gains and the bounds of the integral and the output
        self._pid = (pid.k_p, pid.k_i, pid.k_d, -pid.max_integral, pid.max_integral, -pid.max_output, pid.max_output)
        self._guard = (p.push_guard_range, 2.0 * p.brake, p.push_guard * p.push_guard, p.contact_push)
        self._guard_body = (-p.push_guard_range, *self._guard, p.contact_range)  # `drive`'s guard of the body
        # `drive` narrows the guard's box to the opponents it may cap: not with a cap that pushes back (below 0)
        self._guard_shrinks = p.contact_push >= 0.0 and p.brake > 0.0
        self._static_area = not p.dynamic and ctx.n != 0  # paper 2, Fig. 5: `drive` keeps it in its area

    def report(self, tick: int, sense: Sense | None) -> Report:
        return report_of(tick, self.n, sense, self.role, self.view.pose or (0.0, 0.0, 0.0))

    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        view = self.view
        view.update(tick, sense, order)
        self.order = order
        self.tick = tick
        if order is None or sense is None or view.pose is None:
            return Cmd(tick=tick)
        mem = self.mem
        command = order.command
        if order is not self._planned:  # what follows from the order alone, once per order
            if command != mem.command:
                mem.command, mem.command_since = command, tick
            self.role = order.role or self.role or "defender"
            self.plan = self.make_plan(order)
            self._planned = order
            # `keep_setpiece_distance` holds only before this tick (2 s after the command): none for our restart
            # or the keeper (False for the rest of this order), so that most ticks do not ask it
            may = order.command_team not in (self.team, "") and self.role != "goalkeeper"
            self._keep_away_until = mem.command_since + self._ticks_2s if may else -1
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
        if tick < self._keep_away_until and self.keep_setpiece_distance(tick, order, ball):
            return self.position_for_restart(tick, order)
        if self.role == "goalkeeper":
            return self.goalkeeper(tick, order, ball)
        if has_ball:
            return self.with_ball(tick, order, ball)
        return self.without_ball(tick, order, ball)

    def make_plan(self, order: Order) -> Plan:
        key = []  # the teammates' roles, (n, role); a plain loop: a comprehension costs more for three teammates
        for n, mate in self.view.mates.items():
            r = mate[2]
            if n != 0 and (r == "attacker" or r == "defender"):
                key.append((n, r))
        if self.n != 0:
            key.append((self.n, self.role))
        key = tuple(key)  # the areas follow from the roles alone: worked out once per set of roles
        areas = self._areas.get(key)
        if areas is None:
            areas = self._areas[key] = R.areas(dict(key), self.area_params)
        d = order.attack_dir
        # positional, in the fields' order (msgspec looks each keyword's name up):
        # role, area, areas, attacking (`R.is_attacking`), team (a new dict with every order, `RobotView.update`),
        # goal and own goal centres
        return Plan(
            self.role,
            areas.get(self.n, self._defense_area),
            areas,
            order.role_state in _ATTACKING,
            self.view.mates,
            (d * self.half_length, 0.0),
            (-d * self.half_length, 0.0),
        )
