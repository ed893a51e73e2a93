"""The strategy contract: what a team's code must provide to play.

A strategy is a `Strategy` record registered by name (built-ins here, a user's
own through the Python entry-point group ``soccer_arena.strategies``). It makes
two kinds of brains:

* a **team brain** runs in the base station. Every comm period it gets the
  robots' latest reports (R_n_B) and the referee's latest state, and returns
  one `Order` (B_R_n) per robot: the fused P_A, P_B, P_ball, the command C, the
  strategy S and the robot's role (paper 2, eq. 5).
* a **robot brain** runs in the robot process. Every tick it gets the robot's
  `Sense` (G_R_n, noisy, never ground truth) and the latest `Order` that has
  arrived over Wi-Fi (None before the first one), and returns a `Cmd` (R_n_G).
  Every comm period it also fills the robot's `Report`.

Brains must be deterministic given their inputs and the `random.Random` they
are handed: no wall clock, no global `random`, no threads.

**Parameters.** A strategy declares the numbers a team may tune in
`Strategy.params`, one `Param` each: its name, default (whose Python type,
bool, int, float or str, is the parameter's type), range (`low`..`high` for
numbers, `choices` for strings), unit and meaning. A match sets them per team
(`MatchConfig.params`, ``[params.a] kick_speed = 7.0`` in a match file,
``arena match --param a.kick_speed=7.0``); `arena strategies --params NAME`
lists them. A brain factory reads the values its team was given with
`ctx.param_values(declared)`: every declared name, the given value or the
default, each checked (`check_value`). With no value given, a strategy must
play exactly as before (the same digests). Values a strategy does not declare
are refused with a `ConfigError` before the match starts
(`registry.check_params`), and again by `ctx.param_values` in the process that
builds the brain.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from arena.config import ConfigError, MatchConfig, ParamValue
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, Sense

POLICY_PREFIX = "policy:"  # a policy file's strategy name: policy:PATH (learned.py, policy_file.py)


def report_of(
    tick: int, n: int, sense: Sense | None, role: str, pose: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> Report:
    """A robot's report to its base station: what its `sense` says, or `pose` (its best guess) before any."""
    if sense is None:
        return Report(tick=tick, robot=n, pose=Pose(x=pose[0], y=pose[1], theta=pose[2]), role=role)
    # positional, in Report's fields' order: msgspec looks each keyword's name up (every robot, every report tick)
    return Report(tick, n, sense.pose, sense.ball, sense.robots, sense.has_ball, role)


@dataclass(frozen=True)
class Param:
    """One tunable parameter of a strategy: `default`'s type is the parameter's type."""

    name: str
    default: ParamValue
    low: float | None = None  # numbers: the least value accepted
    high: float | None = None  # numbers: the greatest value accepted
    unit: str = ""  # e.g. "m/s"; "" for a pure number
    meaning: str = ""
    choices: tuple[str, ...] = ()  # strings: the values accepted (empty: any)

    @property
    def type(self) -> str:
        """bool, int, float or str."""
        return type(self.default).__name__

    def describe(self) -> str:
        """`kick_speed (float 2..8 m/s)`: the name with its type and range, for error lines."""
        if self.choices:
            span = "|".join(self.choices)
        elif self.low is not None or self.high is not None:
            span = f"{self.low:g}..{self.high:g}" + (f" {self.unit}" if self.unit else "")
        else:
            span = ""
        return f"{self.name} ({self.type}{' ' + span if span else ''})"

    def check(self, value: object) -> ParamValue:
        """`value` as this parameter's type (an int is a float's whole number); ConfigError saying why not."""
        kind = type(self.default)
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if type(value) is not kind:
            raise ConfigError(f"{self.name} must be {self.type}, got {value!r}")
        if kind is float and not math.isfinite(value):  # type: ignore[arg-type]
            raise ConfigError(f"{self.name} must be finite, got {value!r}")
        if kind in (int, float):
            if (self.low is not None and value < self.low) or (self.high is not None and value > self.high):  # type: ignore[operator]
                raise ConfigError(f"{self.name} must be in {self.low:g}..{self.high:g}, got {value!r}")
        if kind is str and self.choices and value not in self.choices:
            raise ConfigError(f"{self.name} must be one of {', '.join(self.choices)}, got {value!r}")
        return value  # type: ignore[return-value]


def check_values(strategy: str, declared: tuple[Param, ...], given: dict[str, object]) -> dict[str, ParamValue]:
    """`given` checked against `declared`: name -> value of the right type; ConfigError, one line naming
    the strategy's parameters, for an unknown name, a wrong type or a value out of range."""
    table = {p.name: p for p in declared}
    valid = ", ".join(p.describe() for p in declared) if declared else "none"
    out = {}
    for name, value in given.items():
        p = table.get(name)
        if p is None:
            raise ConfigError(f"strategy {strategy} has no parameter {name!r}; its parameters: {valid}")
        try:
            out[name] = p.check(value)
        except ConfigError as exc:
            raise ConfigError(f"strategy {strategy}: {exc}; its parameters: {valid}") from None
    return out


class _Given:
    """What a brain factory reads of its team's parameters (TeamContext and RobotContext)."""

    cfg: MatchConfig
    team: str

    @property
    def params(self) -> dict[str, ParamValue]:
        """The parameter values this team was given (`MatchConfig.params`), unchecked; {} for none."""
        return self.cfg.params.get(self.team, {})

    def param_values(self, declared: tuple[Param, ...]) -> dict[str, ParamValue]:
        """Every declared parameter: the value given to this team, checked, or its default."""
        given = check_values(self.cfg.strategy_of(self.team), declared, self.params)
        return {p.name: given.get(p.name, p.default) for p in declared}


@dataclass(frozen=True)
class TeamContext(_Given):
    cfg: MatchConfig
    team: str  # "a" or "b"
    rng: random.Random


@dataclass(frozen=True)
class RobotContext(_Given):
    cfg: MatchConfig
    team: str
    n: int  # robot number, 0 = goalkeeper
    rng: random.Random


class TeamBrain(Protocol):
    def step(self, tick: int, reports: dict[int, Report], referee: Referee | None) -> dict[int, Order]:
        """Orders for every robot number 0..robots-1, stamped with `tick`."""
        ...


class RobotBrain(Protocol):
    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        """The command for this tick, stamped with `tick`."""
        ...

    def report(self, tick: int, sense: Sense | None) -> Report:
        """What the robot tells its base station, stamped with `tick`."""
        ...


@dataclass(frozen=True)
class Strategy:
    name: str
    make_team: Callable[[TeamContext], TeamBrain]
    make_robot: Callable[[RobotContext], RobotBrain]
    aliases: tuple[str, ...] = ()
    description: str = ""
    params: tuple[Param, ...] = ()  # the tunable parameters, in the order `arena strategies --params` lists them
