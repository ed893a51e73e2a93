"""The IRIS base station brain.

Base station (`IrisTeam`), every comm period:

* fuses the reports into P_A, P_B, P_ball (eq. 5, :mod:`arena.strategies.world`);
* chooses S1/S2/S3 from the score (eq. 5, :func:`arena.strategies.roles.choose_strategy`);
* decides possession (inputs b and b-bar) and runs the role FSM of Fig. 6 with
  the areas and n_d = ceil(n/2) of eq. 6 (:mod:`arena.strategies.roles`); static roles never
  swap, dynamic roles swap with inputs a and d;
* relays the referee command C and sends one `Order` per robot;
* a robot the referee sends off (its RED_CARD, DOUBLE_YELLOW or REPAIR_OUT
  command) leaves the roles, and eq. 6 assigns the robots left.
"""

from __future__ import annotations

import math

from msgspec.structs import replace

from arena.schemas.messages import Order, Referee, Report, TeamPose
from arena.schemas.vocabulary import SEND_OFF, SET_PIECES
from arena.strategies import roles as R
from arena.strategies.base import TeamContext
from arena.strategies.iris.params import PLAY, IrisParams
from arena.strategies.world import TeamModel


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
        bx, by = ball
        opp = own = (
            math.inf
        )  # the nearest opponent's and own robot's distances to the ball (plain loops: no generators)
        for o in self.model.opponents:
            d = math.hypot(o.x - bx, o.y - by)  # S.dist
            if d < opp:
                opp = d
        for x, y, _, _ in self.model.own.values():
            d = math.hypot(x - bx, y - by)
            if d < own:
                own = d
        if opp < self.p.possession_radius and opp < own:
            return "opponent", None
        return "", None

    def step(self, tick: int, reports: dict[int, Report], referee: Referee | None) -> dict[int, Order]:
        self.model.update(tick, reports)
        if referee is not None:
            for cmd in referee.commands:  # a robot sent off leaves the roles (eq. 6 for the robots left)
                if cmd.name in SEND_OFF and cmd.team == self.team and cmd.robot > 0:
                    self.roles.send_off(cmd.robot)
        c = R.referee_fields(self.team, referee, default_attack_dir=1 if self.team == "a" else -1)
        command, cteam, attack_dir = c["command"], c["command_team"], c["attack_dir"]
        possession, holder = self.possession(tick)
        if command == PLAY:
            xy: dict[int, tuple[float, float]] = {}  # each own robot's position, and its x along the attack direction
            u: dict[int, float] = {}
            for n, v in self.model.own.items():
                xy[n] = (v[0], v[1])
                u[n] = attack_dir * v[0]
            self.roles.update(possession, holder, u, xy)
        elif command in SET_PIECES and cteam:
            # A set piece gives the ball to one side: its team attacks (b), the other defends (b-bar).
            self.roles.update("own" if cteam == self.team else "opponent", None, {}, {})
        role_of = {0: "goalkeeper", **self.roles.roles()}
        # The messages below built with positional arguments in their fields' order (msgspec looks each keyword's
        # name up), their lists in plain loops (a comprehension is a frame of its own).
        # TeamPose: robot, x, y, theta, age, role
        own_poses: list[TeamPose] = []
        for n, v in sorted(self.model.own.items()):
            own_poses.append(TeamPose(n, v[0], v[1], v[2], tick - v[3], role_of.get(n, "")))
        opponents: list[TeamPose] = []
        for o in self.model.opponents:
            opponents.append(TeamPose(-1, o.x, o.y, 0.0, tick - o.tick))
        ball = self.model.ball_xy(tick)
        bx, by, ball_age = (ball[0], ball[1], self.model.ball.age(tick)) if ball is not None else (0.0, 0.0, 0)
        # What every robot's order shares, the robot's own fields at their defaults: tick, robot, command,
        # command_team, spot_x, spot_y, attack_dir, strategy, role, role_state, own, opponents, ball_valid,
        # ball_x, ball_y, ball_z, ball_age
        common = Order(
            tick,
            0,
            c["command"],
            c["command_team"],
            c["spot_x"],
            c["spot_y"],
            c["attack_dir"],
            c["strategy"],
            "",
            0,
            own_poses,
            opponents,
            ball is not None,
            bx,
            by,
            0.0,
            ball_age,
        )
        state = self.roles.state
        # each robot's order is a copy of `common` made in C (`replace`), cheaper than building it again
        orders: dict[int, Order] = {}
        for n in range(self.cfg.robots):
            orders[n] = replace(common, robot=n, role=role_of.get(n, "defender"), role_state=state.get(n, 0))
        return orders
