"""The engine's side of a scenario: its steps applied to the physics at their ticks.

A scenario (docs/scenarios.md) travels in the match configuration
(`MatchConfig.scenario`), so every engine, in process or its own OS process,
plays the same steps. Each `Step` fires once: at its tick `at`, or at the
first tick at which its `when` holds (`Condition`, judged on the world before
the tick's frames are published). The engine applies the step's teleports
(`TeleportBall`, `TeleportRobot`, the SSL simulation protocol's semantics;
`present = false` parks the robot as a red card would); the referee applies
its `RefereeOverride`s (rules/referee_box.py `Forced`), which is why those
need a tick `at`. Their effect is in every frame sent after the tick, so in
the digest; a plain match has no steps and plays exactly as before.

The same messages drive a live session (`--realtime` or `--live`): `arena
operator` puts `Operator` frames, and the engine and the referee take them at
their next tick (`OperatorInbox`) and log what they applied, with the tick.
A frame counts only with the operator's MAC (runtime/mac.py; the others are
counted per key as forged) and a `seq` above the last one's (a replayed frame
is refused). Wherever an action comes from (an operator frame, a scenario
step), it is range-checked first (`check_action`: finite, inside the fence,
speeds within the robot model's limits); one that is not is refused with its
reason, counted, and the match goes on.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import msgspec

from arena.config import MatchConfig
from arena.schemas.keys import MAX_FRAME_BYTES, OPERATOR_PRINCIPAL
from arena.schemas.messages import (
    Cmd,
    Condition,
    ControlRobot,
    Operator,
    Referee,
    RefereeOverride,
    Step,
    TeleportBall,
    TeleportRobot,
)
from arena.sim.physics import Physics
from arena.sim.physics.bodies import FENCE_RADIUS
from arena.sim.physics.placement import PARK_GAP

_OPERATOR = msgspec.msgpack.Decoder(Operator)
GRAVITY = 9.81  # [m/s^2] the highest a ball can be teleported to is where the fastest kick could lift it


def _out_of(name: str, value: float | None, bound: float) -> str | None:
    """Why `value` is not a finite number within +-`bound` (None: it is, or it is not given)."""
    if value is None:
        return None
    if not math.isfinite(value):
        return f"{name} is not finite"
    if abs(value) > bound:
        return f"{name} = {value:g} is beyond +-{bound:g}"
    return None


def _speed(name: str, parts: tuple[float | None, ...], limit: float) -> str | None:
    given = [v for v in parts if v is not None]
    if not all(math.isfinite(v) for v in given):
        return f"{name} is not finite"
    speed = math.hypot(*given) if given else 0.0
    return f"{name} {speed:g} is above the model's {limit:g}" if speed > limit else None


def check_action(cfg: MatchConfig, a: object) -> str | None:
    """Why a teleport or an override cannot be applied in this match (None: it can).

    Every number finite; a position inside the fence (the field's lines plus `runoff`; a robot also
    where a parked one stands, beyond it: a replay with substitution teleports to recorded poses);
    a robot's speeds within its model's `max_speed` and `max_omega`; a ball no faster than the
    model's kick plus its top speed, and no higher than such a kick could lift it; a robot that plays."""
    f, rp = cfg.field, cfg.robot
    fx, fy = f.length / 2 + f.runoff, f.width / 2 + f.runoff
    parked_x = fx + FENCE_RADIUS + PARK_GAP
    ball = rp.kick_max_speed + rp.max_speed
    match a:
        case TeleportBall():
            checks = (
                _out_of("x", a.x, fx),
                _out_of("y", a.y, fy),
                _out_of("z", a.z, ball * ball / (2 * GRAVITY)),
                _speed("ball speed", (a.vx, a.vy, a.vz), ball),
            )
        case TeleportRobot():
            checks = (
                None if a.robot < cfg.robots else f"robot {a.robot}: the match has {cfg.robots} per team",
                _out_of("x", a.x, parked_x),
                _out_of("y", a.y, fy),
                _out_of("orientation", a.orientation, 1e3),
                _speed("speed", (a.vx, a.vy), rp.max_speed),
                _out_of("omega", a.omega, rp.max_omega),
            )
        case RefereeOverride():
            checks = (
                _out_of("x", a.x, fx),
                _out_of("y", a.y, fy),
                None if -1 <= a.robot < cfg.robots else f"robot {a.robot}: the match has {cfg.robots} per team",
            )
        case _:
            return None
    return next((c for c in checks if c), None)


def referee_steps(steps: tuple[Step, ...]) -> list[tuple[int, RefereeOverride]]:
    """(tick, override) of every referee override, in step order (the referee's share)."""
    return sorted(((s.at, a) for s in steps for a in s.actions if isinstance(a, RefereeOverride)), key=lambda p: p[0])


class Director:
    """Fires the engine's share of the steps: `observe` every referee frame, `act(k)` every tick.

    `refuse(why)`: called for a step's action that fails `check_action` (it is not applied)."""

    def __init__(self, cfg: MatchConfig, physics: Physics, refuse: Callable[[str], None] | None = None):
        self.cfg = cfg
        self.physics = physics
        self.refuse = refuse
        mine = [s for s in cfg.scenario.steps if any(not isinstance(a, RefereeOverride) for a in s.actions)]
        self.at: dict[int, list[Step]] = {}  # by tick: a replay with substitution has a step every tick
        for s in mine:
            if s.at >= 0:
                self.at.setdefault(s.at, []).append(s)
        self.waiting = [s for s in mine if s.at < 0 and s.when is not None]  # conditions not yet met
        self.fired = 0  # steps done
        self.seen: set[str] = set()  # referee commands the engine has applied
        self.driven: dict[tuple[str, int], tuple[int, Cmd]] = {}  # ControlRobot: robot -> (last tick, command)
        self.moved: list[dict[str, object]] = []  # teleports put elsewhere (safely, or onto another robot)
        self.tick = 0

    def observe(self, frame: Referee) -> None:
        self.seen.update(c.name for c in frame.commands)

    def act(self, k: int) -> None:
        self.tick = k
        due = self.at.pop(k, [])
        if self.waiting:
            met = [s for s in self.waiting if self.holds(s.when)]
            if met:
                self.waiting = [s for s in self.waiting if s not in met]
                due += met
        for step in due:
            self.fired += 1
            placed: list[tuple[str, int]] = []  # robots this step put down, in order
            for action in step.actions:
                why = check_action(self.cfg, action)
                if why is not None:
                    if self.refuse is not None:
                        self.refuse(f"step at tick {step.at}: {why}")
                    continue
                self.apply(action)
                if isinstance(action, TeleportRobot) and action.present and not action.by_force:
                    self.unstack((action.team, action.robot), placed)
                    placed.append((action.team, action.robot))

    def drive(self, k: int) -> None:
        """The robots under a `ControlRobot` at tick k get its command instead of their process's."""
        for (team, n), (last, cmd) in list(self.driven.items()):
            if k > last:
                del self.driven[(team, n)]
            else:
                self.physics.set_command(team, n, cmd)

    def holds(self, c: Condition) -> bool:
        ph = self.physics
        bx, by, *_ = ph.ball_state()
        if c.ball_in is not None and not c.ball_in.contains(bx, by):
            return False
        if c.robot_in is not None:
            team, n = c.robot.split("/")
            x, y, _ = ph.robot_pose(team, int(n))
            if not c.robot_in.contains(x, y):
                return False
        if c.command and c.command not in self.seen:
            return False
        if c.possession:
            holder = ph.holder()
            if holder is None or holder[0] != c.possession:
                return False
        return True

    def apply(self, action: object) -> None:
        match action:
            case TeleportBall():
                self.teleport_ball(action)
            case TeleportRobot():
                self.teleport_robot(action)
            case ControlRobot():
                a = action
                cmd = Cmd(
                    tick=self.tick,
                    vx=a.vx,
                    vy=a.vy,
                    omega=a.omega,
                    kick_speed=a.kick_speed,
                    kick_lob=a.kick_lob,
                    dribbler=a.dribbler,
                )
                self.driven[(a.team, a.robot)] = (self.tick + a.ticks - 1, cmd)

    def teleport_ball(self, a: TeleportBall) -> None:
        ph = self.physics
        x0, y0, _, vx0, vy0, _ = ph.ball_state()
        x = x0 if a.x is None else a.x
        y = y0 if a.y is None else a.y
        if a.by_force:  # rolled from where it lies, fast enough that rolling friction stops it on (x, y)
            d = math.hypot(x - x0, y - y0)
            v = math.sqrt(2.0 * self.cfg.ball.rolling_decel * d)
            vx, vy = (v * (x - x0) / d, v * (y - y0) / d) if d > 0 else (0.0, 0.0)
            ph.teleport_ball(x0, y0, 0.0, vx, vy, 0.0)
            return
        if a.safely:
            r = self.cfg.ball.radius
            nx, ny = free_spot(x, y, r, self.bodies(skip=None, ball=False), self.cfg)
            if (nx, ny) != (x, y):
                self.moved.append({"tick": self.tick, "ball": True, "x": round(nx, 3), "y": round(ny, 3)})
            x, y = nx, ny
        z, vz = (0.0, 0.0) if a.roll else (a.z, a.vz)
        ph.teleport_ball(x, y, z, vx0 if a.vx is None else a.vx, vy0 if a.vy is None else a.vy, vz)

    def teleport_robot(self, a: TeleportRobot) -> None:
        ph = self.physics
        if a.robot >= self.cfg.robots:
            return  # validated by the scenario loader; a hand-made config cannot move a robot that is not there
        if not a.present:
            ph.park_robot(a.team, a.robot)
            return
        x0, y0, th0 = ph.robot_pose(a.team, a.robot)
        vx0, vy0, w0 = ph.robot_velocity(a.team, a.robot)
        x = x0 if a.x is None else a.x
        y = y0 if a.y is None else a.y
        if a.by_force:  # pushed from where it stands, as fast as its acceleration lets it stop on (x, y)
            rp = self.cfg.robot
            d = math.hypot(x - x0, y - y0)
            v = min(rp.max_speed, math.sqrt(2.0 * rp.max_accel * d))
            if d > 0:
                ph.push_robot(a.team, a.robot, v * (x - x0) / d, v * (y - y0) / d)
            return
        if a.safely:
            reach = self.cfg.robot.size * math.sqrt(0.5)
            x, y = self.resettle(
                (a.team, a.robot), x, y, free_spot(x, y, reach, self.bodies((a.team, a.robot)), self.cfg)
            )
        pose = (x, y, th0 if a.orientation is None else a.orientation)
        twist = (vx0 if a.vx is None else a.vx, vy0 if a.vy is None else a.vy, w0 if a.omega is None else a.omega)
        ph.teleport_robot(a.team, a.robot, pose, twist)

    def bodies(self, skip: tuple[str, int] | None, ball: bool = True, only=None) -> list[tuple[float, float, float]]:
        """(x, y, radius) of the robots on the field (but `skip`; of `only`, if given) and the ball."""
        ph, reach = self.physics, self.cfg.robot.size * math.sqrt(0.5)
        parked = set(ph.parked())
        out = []
        for team in ("a", "b"):
            for n in range(self.cfg.robots):
                r = (team, n)
                if r != skip and r not in parked and (only is None or r in only):
                    out.append((*ph.robot_pose(team, n)[:2], reach))
        if ball:
            bx, by, *_ = ph.ball_state()
            out.append((bx, by, self.cfg.ball.radius))
        return out

    def resettle(self, r: tuple[str, int], x: float, y: float, spot: tuple[float, float]) -> tuple[float, float]:
        if spot != (x, y):
            self.moved.append(
                {"tick": self.tick, "robot": f"{r[0]}/{r[1]}", "x": round(spot[0], 3), "y": round(spot[1], 3)}
            )
        return spot

    def unstack(self, r: tuple[str, int], placed: list[tuple[str, int]]) -> None:
        """A robot teleported onto one this step already put down goes to the nearest spot clear of them."""
        ph = self.physics
        if r in ph.parked():
            return
        x, y, th = ph.robot_pose(*r)
        reach = self.cfg.robot.size * math.sqrt(0.5)
        others = self.bodies(r, ball=False, only=set(placed))
        if any(math.hypot(x - ox, y - oy) < OVERLAP * self.cfg.robot.size for ox, oy, _ in others):
            nx, ny = self.resettle(r, x, y, free_spot(x, y, reach, others, self.cfg))
            ph.teleport_robot(r[0], r[1], (nx, ny, th), ph.robot_velocity(*r))


def free_spot(
    x: float, y: float, radius: float, bodies: list[tuple[float, float, float]], cfg: MatchConfig
) -> tuple[float, float]:
    """SSL `teleport_safely`: (x, y) if a body of `radius` there touches none of `bodies` (x, y, radius),
    else the nearest such spot on rings round it (every FREE_STEP metres, inside the fence, out of the
    goals); deterministic. (x, y) if nothing within FREE_RINGS rings fits."""
    f = cfg.field
    xmax, ymax = f.length / 2 + f.runoff - radius, f.width / 2 + f.runoff - radius
    goal_x, goal_y = f.length / 2 - radius, f.goal_width / 2 + radius

    def free(cx: float, cy: float) -> bool:
        if abs(cx) > xmax or abs(cy) > ymax or (abs(cx) > goal_x and abs(cy) < goal_y):
            return False
        return all(math.hypot(cx - bx, cy - by) >= radius + br + FREE_GAP for bx, by, br in bodies)

    if all(math.hypot(x - bx, y - by) >= radius + br for bx, by, br in bodies):
        return x, y
    for ring in range(1, FREE_RINGS + 1):
        rad = ring * FREE_STEP
        count = 8 * ring
        for k in range(count):
            a = (k + 1) // 2 * (2 * math.pi / count) * (1 if k % 2 else -1)
            cx, cy = x + rad * math.cos(a), y + rad * math.sin(a)
            if free(cx, cy):
                return cx, cy
    return x, y


FREE_STEP = 0.05  # [m] between the rings `free_spot` tries
FREE_RINGS = 80  # up to 4 m away
FREE_GAP = 0.01  # [m] clearance between bodies put down
OVERLAP = 0.9  # two robots whose centres are closer than this many sizes were put onto each other (not a slop)


class OperatorInbox:
    """A live session's `operator` frames: taken at each tick, the wanted kinds checked, kept and logged.

    Only frames with the operator's MAC get here (the others are counted as forged on the key), and
    only one whose `seq` is above the last one's counts (a genuine frame put again is refused)."""

    def __init__(self, node, kinds: tuple[type, ...]):
        self.key = key = node.keys.operator()
        self.cfg = node.cfg
        self.rejections = node.rejections
        verify, on_forged = node.mac_check(key, OPERATOR_PRINCIPAL)
        self.channel = node.transport.subscribe(key, verify=verify, on_forged=on_forged)
        self.kinds = kinds
        self.seq = -1  # the last frame's
        self.log: list[dict[str, object]] = []  # {tick, seq, action}: what was applied, for the summary
        self.refused: list[dict[str, object]] = []  # {tick, seq, action, why}: what was not

    def take(self, k: int) -> list:
        out = []
        while (raw := self.channel.try_recv()) is not None:
            if len(raw) > MAX_FRAME_BYTES:
                self.rejections.reject(self.key, "too-large", f"{len(raw)} bytes, at most {MAX_FRAME_BYTES}")
                continue
            try:
                msg = _OPERATOR.decode(raw)
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self.rejections.reject(self.key, "malformed", str(exc)[:120])
                continue
            if msg.seq <= self.seq:
                self.rejections.reject(self.key, "out-of-sequence", f"seq {msg.seq} after {self.seq}")
                continue
            self.seq = msg.seq
            for a in msg.actions:
                if not isinstance(a, self.kinds):
                    continue
                why = check_action(self.cfg, a)
                if why is not None:  # (not the action itself: it may hold a NaN, which JSON has not)
                    self.rejections.reject(self.key, "invalid", why)
                    self.refused.append({"tick": k, "seq": msg.seq, "type": type(a).__name__, "why": why})
                    continue
                out.append(a)
                self.log.append({"tick": k, "seq": msg.seq, "action": msgspec.to_builtins(a)})
        return out

    def summary(self) -> dict[str, object]:
        """The summary's share: `operator` (what was applied) and, if any, `operator_refused`."""
        return {"operator": self.log} | ({"operator_refused": self.refused} if self.refused else {})


def operator_inbox(node, kinds: tuple[type, ...]) -> OperatorInbox | None:
    """The node's operator inbox in a live session (`--realtime`, `--live`); None in a lockstep match,
    which stays a pure function of its configuration and seed."""
    cfg = node.cfg
    return OperatorInbox(node, kinds) if cfg.realtime or cfg.live >= 0 else None
