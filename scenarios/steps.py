"""A scenario's `start` and `step` tables as the messages the engine and the referee apply.

Each builder validates its table (scenarios/bounds.py for the numbers) and
raises `ValueError` naming the key below `scenario[i]`: teleports (SSL
`TeleportBall`, `TeleportRobot`), referee decisions, robots driven
(`ControlRobot`), parked and killed processes, link changes, and the
conditions of `when`."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from arena.config import ConfigError, MatchConfig, ProcessId
from arena.rules.referee_box import TEAM_COMMANDS
from arena.runtime.links import resolve
from arena.scenarios.bounds import check_ball, check_control, check_region, check_robot, check_spot
from arena.schemas.messages import (
    Condition,
    ControlRobot,
    KillProcess,
    RefereeOverride,
    Region,
    SetLink,
    Step,
    TeleportBall,
    TeleportRobot,
)
from arena.schemas.vocabulary import REF_COMMANDS, TEAMS

if TYPE_CHECKING:
    from arena.scenarios.model import BallSpec, ControlSpec, RefereeSpec, RobotSpec, Start, StepSpec, When

DEFAULTS = MatchConfig()  # the field, robot and timing a scenario plays with


def region(values: list[float] | None, where: str) -> Region | None:
    if values is None:
        return None
    check_region(values, where)
    return Region(x0=values[0], y0=values[1], x1=values[2], y1=values[3])


def robot_id(text: str, robots: int, where: str) -> tuple[str, int]:
    parts = text.split("/")
    if len(parts) != 2 or parts[0] not in TEAMS or not parts[1].isdigit() or not 0 <= int(parts[1]) < robots:
        raise ValueError(f"{where}: {text!r} is not a robot of this match (a/0 .. b/{robots - 1})")
    return parts[0], int(parts[1])


def ball_action(b: BallSpec, where: str) -> TeleportBall:
    check_ball(b, DEFAULTS, where)
    return TeleportBall(
        x=b.x, y=b.y, z=b.z, vx=b.vx, vy=b.vy, vz=b.vz, by_force=b.by_force, safely=b.safely, roll=b.roll
    )


def robot_action(r: RobotSpec, robots: int, where: str) -> TeleportRobot:
    team, n = robot_id(r.robot, robots, f"{where}.robot")
    check_robot(r, DEFAULTS, where)
    return TeleportRobot(
        team=team,
        robot=n,
        x=r.x,
        y=r.y,
        orientation=r.theta,
        vx=r.vx,
        vy=r.vy,
        omega=r.omega,
        present=r.present,
        by_force=r.by_force,
        safely=r.safely,
    )


def control_action(c: ControlSpec, robots: int, dt: float, time_limit: float, where: str) -> ControlRobot:
    team, n = robot_id(c.robot, robots, f"{where}.robot")
    check_control(c, DEFAULTS, time_limit, where)
    return ControlRobot(
        team=team,
        robot=n,
        ticks=max(1, int(round(c.seconds / dt))),
        vx=c.vx,
        vy=c.vy,
        omega=c.omega,
        kick_speed=c.kick_speed,
        kick_lob=c.kick_lob,
        dribbler=c.dribbler,
    )


def referee_action(r: RefereeSpec, robots: int, where: str) -> RefereeOverride:
    if r.command not in REF_COMMANDS:
        raise ValueError(f"{where}.command: {r.command!r} is not an MSL RefBox command")
    if r.team not in ("a", "b", ""):
        raise ValueError(f"{where}.team: {r.team!r} (a, b or empty)")
    if r.command in ("FREEKICK", "THROWIN", "DROP_BALL") and (r.x is None or r.y is None):
        raise ValueError(f"{where}: {r.command} needs the ball spot x and y")
    if r.command in TEAM_COMMANDS and not r.team:
        raise ValueError(f"{where}.team: {r.command} needs the team it is for (a or b)")
    check_spot(r.x, r.y, DEFAULTS, where)
    n = robot_id(r.robot, robots, f"{where}.robot")[1] if r.robot else -1
    if (r.command in ("YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW", "REPAIR_OUT")) != (n >= 0):
        raise ValueError(f"{where}.robot: cards and REPAIR_OUT need a robot, other commands none")
    return RefereeOverride(command=r.command, team=r.team, x=r.x, y=r.y, robot=n)


def start_steps(st: Start, robots: int, where: str) -> list[Step]:
    actions: list = []
    for i, r in enumerate(st.robots):
        actions.append(robot_action(r, robots, f"{where}.robots[{i}]"))
    if st.ball is not None:
        actions.append(ball_action(st.ball, f"{where}.ball"))
    actions.append(referee_action(st.referee, robots, f"{where}.referee"))
    return [Step(at=0, actions=actions)]


def step_actions(s: StepSpec, robots: int, where: str, dt: float = 0.01, time_limit: float = 0.0) -> list:
    """What a step does, in a fixed order: robots, parked robots, the ball, the referee, the links,
    the kills, the robots driven."""
    actions: list = [robot_action(r, robots, f"{where}.robots[{i}]") for i, r in enumerate(s.robots)]
    for i, name in enumerate(s.park):
        team, n = robot_id(name, robots, f"{where}.park[{i}]")
        actions.append(TeleportRobot(team=team, robot=n, present=False))
    if s.ball is not None:
        actions.append(ball_action(s.ball, f"{where}.ball"))
    if s.referee is not None:
        if s.at is None:
            raise ValueError(f"{where}.referee: a referee command needs `at`; the referee does not see `when`")
        actions.append(referee_action(s.referee, robots, f"{where}.referee"))
    if s.link is not None:
        if s.at is None:
            raise ValueError(f"{where}.link: a link change needs `at`; every receiver applies it at that tick")
        try:
            resolve(s.link.preset, s.link.overrides)
        except ConfigError as exc:
            raise ValueError(f"{where}.link: {exc}") from None
        actions.append(SetLink(preset=s.link.preset, overrides=s.link.overrides))
    actions += kill_actions(s, robots, where)
    actions += [control_action(c, robots, dt, time_limit, f"{where}.control[{i}]") for i, c in enumerate(s.control)]
    if not actions:
        raise ValueError(f"{where}: a step does nothing (give ball, robots, referee, park, link, kill or control)")
    return actions


def kill_actions(s: StepSpec, robots: int, where: str) -> list:
    out = []
    for i, name in enumerate(s.kill):
        try:
            pid = ProcessId.parse(name)
        except ConfigError:
            pid = None
        if pid is None or pid.kind not in ("robot", "basestation") or pid.robot >= robots:
            raise ValueError(f"{where}.kill[{i}]: {name!r} is not a robot or base station of this match")
        if s.at is None:
            raise ValueError(f"{where}.kill: killing a process needs `at`; the process itself stops at that tick")
        out.append(KillProcess(process=str(pid)))
    return out


def condition(w: When, robots: int, where: str) -> Condition:
    if w.robot_in is not None:
        robot_id(w.robot, robots, f"{where}.robot")
    if w.command and w.command not in REF_COMMANDS:
        raise ValueError(f"{where}.command: {w.command!r} is not an MSL RefBox command")
    if w.possession not in ("a", "b", ""):
        raise ValueError(f"{where}.possession: {w.possession!r} (a or b)")
    cond = Condition(
        ball_in=region(w.ball_in, f"{where}.ball_in"),
        robot=w.robot,
        robot_in=region(w.robot_in, f"{where}.robot_in"),
        command=w.command,
        possession=w.possession,
    )
    if cond == Condition():
        raise ValueError(f"{where}: an empty condition")
    return cond


def step_of(s: StepSpec, robots: int, dt: float, where: str, time_limit: float = 0.0) -> Step:
    if (s.at is None) == (s.when is None):
        raise ValueError(f"{where}: give exactly one of `at` (seconds) and `when` (a condition)")
    actions = step_actions(s, robots, where, dt, time_limit)
    if s.at is not None:
        if not (math.isfinite(s.at) and s.at >= 0):
            raise ValueError(f"{where}.at: seconds >= 0, got {s.at}")
        return Step(at=int(round(s.at / dt)), actions=actions)
    assert s.when is not None
    return Step(at=-1, when=condition(s.when, robots, f"{where}.when"), actions=actions)
