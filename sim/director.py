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
"""

from __future__ import annotations

import math

import msgspec

from arena.runtime.config import MatchConfig
from arena.schemas.messages import Condition, Operator, Referee, RefereeOverride, Step, TeleportBall, TeleportRobot
from arena.sim.physics import Physics

_OPERATOR = msgspec.msgpack.Decoder(Operator)


def referee_steps(steps: tuple[Step, ...]) -> list[tuple[int, RefereeOverride]]:
    """(tick, override) of every referee override, in step order (the referee's share)."""
    return sorted(((s.at, a) for s in steps for a in s.actions if isinstance(a, RefereeOverride)), key=lambda p: p[0])


class Director:
    """Fires the engine's share of the steps: `observe` every referee frame, `act(k)` every tick."""

    def __init__(self, cfg: MatchConfig, physics: Physics):
        self.cfg = cfg
        self.physics = physics
        mine = [s for s in cfg.scenario.steps if any(not isinstance(a, RefereeOverride) for a in s.actions)]
        self.at: dict[int, list[Step]] = {}  # by tick: a replay with substitution has a step every tick
        for s in mine:
            if s.at >= 0:
                self.at.setdefault(s.at, []).append(s)
        self.waiting = [s for s in mine if s.at < 0 and s.when is not None]  # conditions not yet met
        self.fired = 0  # steps done
        self.seen: set[str] = set()  # referee commands the engine has applied

    def observe(self, frame: Referee) -> None:
        self.seen.update(c.name for c in frame.commands)

    def act(self, k: int) -> None:
        due = self.at.pop(k, [])
        if self.waiting:
            met = [s for s in self.waiting if self.holds(s.when)]
            if met:
                self.waiting = [s for s in self.waiting if s not in met]
                due += met
        for step in due:
            self.fired += 1
            for action in step.actions:
                self.apply(action)

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
        ph.teleport_ball(x, y, a.z, vx0 if a.vx is None else a.vx, vy0 if a.vy is None else a.vy, a.vz)

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
        pose = (x, y, th0 if a.orientation is None else a.orientation)
        twist = (vx0 if a.vx is None else a.vx, vy0 if a.vy is None else a.vy, w0 if a.omega is None else a.omega)
        ph.teleport_robot(a.team, a.robot, pose, twist)


class OperatorInbox:
    """A live session's `operator` frames: taken at each tick, the wanted kinds kept and logged."""

    def __init__(self, node, kinds: tuple[type, ...]):
        self.key = node.keys.operator()
        self.channel = node.transport.subscribe(self.key)
        self.rejections = node.rejections
        self.kinds = kinds
        self.log: list[dict[str, object]] = []  # {tick, seq, action}: what was applied, for the summary

    def take(self, k: int) -> list:
        out = []
        while (raw := self.channel.try_recv()) is not None:
            try:
                msg = _OPERATOR.decode(raw)
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self.rejections.reject(self.key, "malformed", str(exc))
                continue
            for a in msg.actions:
                if isinstance(a, self.kinds):
                    out.append(a)
                    self.log.append({"tick": k, "seq": msg.seq, "action": msgspec.to_builtins(a)})
        return out


def operator_inbox(node, kinds: tuple[type, ...]) -> OperatorInbox | None:
    """The node's operator inbox in a live session (`--realtime`, `--live`); None in a lockstep match,
    which stays a pure function of its configuration and seed."""
    cfg = node.cfg
    return OperatorInbox(node, kinds) if cfg.realtime or cfg.live >= 0 else None
