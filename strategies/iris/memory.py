"""What an IRIS robot remembers between ticks (`Memory`), and what follows from one order alone (`Plan`)."""

from __future__ import annotations

from dataclasses import dataclass

import msgspec

from arena.strategies.iris.params import Vec


@dataclass
class Memory:
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


class Plan(msgspec.Struct):
    """What follows from one order alone: roles, areas, teammates (worked out once per order; never changed).
    A msgspec Struct, not a dataclass: built in C, without an `__init__` frame (a robot builds one every order)."""

    role: str
    area: tuple[float, float]  # (u_min, u_max) [m] of this robot
    areas: dict[int, tuple[float, float]]  # of every outfield teammate with a role
    attacking: bool  # Fig. 6: the team is in attacking mode
    team: dict[int, tuple[float, float, str]]  # the order's teammates: n -> (x [m], y [m], role)
    goal: Vec  # [m] the centre of the goal we attack ...
    own: Vec  # [m] ... and of ours
    # `mates` and `attackers`, worked out at the first ask (a holder asks every tick)
    _mates: tuple[Vec, ...] | None = None
    _attackers: tuple[Vec, ...] | None = None

    @property
    def mates(self) -> tuple[Vec, ...]:
        """Positions [m] of the outfield teammates, by robot number (asked for with the ball only)."""
        mates = self._mates
        if mates is None:
            mates = self._mates = tuple((x, y) for n, (x, y, _) in sorted(self.team.items()) if n != 0)
        return mates

    @property
    def attackers(self) -> tuple[Vec, ...]:
        """Positions [m] of the teammates that are attackers, by robot number."""
        mates = self._attackers
        if mates is None:
            team = sorted(self.team.items())
            mates = self._attackers = tuple((x, y) for n, (x, y, r) in team if n != 0 and r == "attacker")
        return mates
