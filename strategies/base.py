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
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from arena.runtime.config import MatchConfig
from arena.schemas.messages import Cmd, Order, Pose, Referee, Report, Sense


def report_of(
    tick: int, n: int, sense: Sense | None, role: str, pose: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> Report:
    """A robot's report to its base station: what its `sense` says, or `pose` (its best guess) before any."""
    if sense is None:
        return Report(tick=tick, robot=n, pose=Pose(x=pose[0], y=pose[1], theta=pose[2]), role=role)
    return Report(
        tick=tick,
        robot=n,
        pose=sense.pose,
        ball=sense.ball,
        robots=sense.robots,
        has_ball=sense.has_ball,
        role=role,
    )


@dataclass(frozen=True)
class TeamContext:
    cfg: MatchConfig
    team: str  # "a" or "b"
    rng: random.Random


@dataclass(frozen=True)
class RobotContext:
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
