"""IRIS strategy choice and role assignment (paper 2, "IRIS Base Station" and "IRIS Role Assignment").

* Strategy S of eq. 5: S1 when the score is level, S2 (offensive) when losing,
  S3 (defensive) when winning (`choose_strategy`).
* Areas (paper 2, Fig. 5): the defender area runs from our goal line to
  `overlap / 2` = 0.5 m past the centre line, the attacker area from 0.5 m
  behind the centre line to the opponent goal line, so they overlap by 1 m.
  Positions are measured along the attack direction: u = attack_dir * x.
* Eq. 6: n_d = ceil(n / 2) defenders and n_a = n - n_d attackers among the n
  outfield robots (the goalkeeper, robot 0, is not counted).
* Several defenders (attackers) split their area "with a line in the direction
  of the y axis", i.e. into bands of equal depth along u, the first band the
  deepest (`area_of`).
* Fig. 6, the 4-state role FSM with inputs a, b, b-bar, d (`transition`):
  state 1 Attacking Attacker, 2 Attacking Defender, 3 Defending Defender,
  4 Defending Attacker. b (the team gets the ball) moves 3 -> 2 and 4 -> 1;
  b-bar (the team loses the ball) moves 2 -> 3 and 1 -> 4; a (defender to
  attacker) moves 2 -> 1 and 3 -> 4; d (attacker to defender) moves 1 -> 2
  and 4 -> 3.
* Static roles: a and d never fire; robots 1..n_a attack, the others defend.
  Dynamic roles (`RoleAssigner.update`): a defender that gets the ball in the
  attack area becomes an attacker (input a) and the attacker nearest to it
  becomes a defender (input d) to keep eq. 6; likewise an attacker that gets
  the ball in the defensive area becomes a defender and the nearest defender
  an attacker. "Gets the ball" is the moment of capture; a robot still holding
  the ball also triggers the swap when it carries the ball out of its own
  area altogether (past the overlap), so roles never flap inside the overlap.
* A robot sent off (RED_CARD, DOUBLE_YELLOW, REPAIR_OUT) leaves the roles, and
  eq. 6 holds again for the n outfield robots left (`RoleAssigner.send_off`):
  with one left, it is the defender (n_d = ceil(1/2) = 1, n_a = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

S_LEVEL, S_OFFENSIVE, S_DEFENSIVE = 1, 2, 3

ATTACKING_ATTACKER = 1
ATTACKING_DEFENDER = 2
DEFENDING_DEFENDER = 3
DEFENDING_ATTACKER = 4

A, B, B_BAR, D = "a", "b", "b_bar", "d"

TRANSITIONS: dict[tuple[int, str], int] = {
    (DEFENDING_DEFENDER, B): ATTACKING_DEFENDER,
    (DEFENDING_ATTACKER, B): ATTACKING_ATTACKER,
    (ATTACKING_DEFENDER, B_BAR): DEFENDING_DEFENDER,
    (ATTACKING_ATTACKER, B_BAR): DEFENDING_ATTACKER,
    (ATTACKING_DEFENDER, A): ATTACKING_ATTACKER,
    (DEFENDING_DEFENDER, A): DEFENDING_ATTACKER,
    (ATTACKING_ATTACKER, D): ATTACKING_DEFENDER,
    (DEFENDING_ATTACKER, D): DEFENDING_DEFENDER,
}


def transition(state: int, inp: str) -> int:
    """Fig. 6: the next state; an input with no arrow out of `state` leaves it unchanged."""
    return TRANSITIONS.get((state, inp), state)


def is_attacker(state: int) -> bool:
    return state in (ATTACKING_ATTACKER, DEFENDING_ATTACKER)


def is_attacking(state: int) -> bool:
    """The team is in attacking mode (it has the ball) in this state."""
    return state in (ATTACKING_ATTACKER, ATTACKING_DEFENDER)


def role_name(state: int) -> str:
    return "attacker" if is_attacker(state) else "defender"


def referee_fields(team: str, referee, default_attack_dir: int) -> dict:
    """Eq. 5's C and S for `team` from the referee's latest frame, as Order fields.

    Before the first frame: STOP, no spot, S1, and `default_attack_dir`.
    """
    if referee is None:
        return {
            "command": "STOP",
            "command_team": "",
            "spot_x": 0.0,
            "spot_y": 0.0,
            "attack_dir": default_attack_dir,
            "strategy": S_LEVEL,
        }
    a = team == "a"
    own, opp = (referee.score_a, referee.score_b) if a else (referee.score_b, referee.score_a)
    return {
        "command": referee.command,
        "command_team": referee.command_team,
        "spot_x": referee.spot_x,
        "spot_y": referee.spot_y,
        "attack_dir": referee.attack_dir_a if a else -referee.attack_dir_a,
        "strategy": choose_strategy(own, opp),
    }


def choose_strategy(own_score: int, opponent_score: int) -> int:
    """Eq. 5's S: 1 level, 2 offensive (losing), 3 defensive (winning)."""
    if own_score == opponent_score:
        return S_LEVEL
    return S_OFFENSIVE if own_score < opponent_score else S_DEFENSIVE


def n_defenders(n_outfield: int) -> int:
    """Eq. 6: n_d = ceil(n / 2)."""
    return math.ceil(n_outfield / 2)


@dataclass(frozen=True)
class AreaParams:
    field_length: float = 12.0  # [m] goal line to goal line
    overlap: float = 1.0  # [m] width of the shared band around the centre line (paper 2)

    @property
    def defense(self) -> tuple[float, float]:
        """(u_min, u_max) [m] of the whole defensive area."""
        return -self.field_length / 2.0, self.overlap / 2.0

    @property
    def attack(self) -> tuple[float, float]:
        """(u_min, u_max) [m] of the whole attack area."""
        return -self.overlap / 2.0, self.field_length / 2.0


def area_of(role: str, index: int, count: int, p: AreaParams) -> tuple[float, float]:
    """(u_min, u_max) [m] of the `index`-th of `count` robots with `role` (bands, deepest first)."""
    lo, hi = p.defense if role == "defender" else p.attack
    count = max(1, count)
    index = min(max(0, index), count - 1)
    depth = (hi - lo) / count
    if role == "defender":
        return lo + index * depth, lo + (index + 1) * depth
    return hi - (index + 1) * depth, hi - index * depth


def areas(roles: dict[int, str], p: AreaParams) -> dict[int, tuple[float, float]]:
    """Area of every outfield robot given everyone's role (robot numbers in order within a role)."""
    out: dict[int, tuple[float, float]] = {}
    for role in ("defender", "attacker"):
        members = sorted(n for n, r in roles.items() if r == role)
        for i, n in enumerate(members):
            out[n] = area_of(role, i, len(members), p)
    return out


class RoleAssigner:
    """The base station's role state: one Fig. 6 state per outfield robot (1..robots-1)."""

    def __init__(self, robots: int, dynamic: bool, p: AreaParams):
        self.dynamic = dynamic
        self.p = p
        outfield = list(range(1, robots))
        n_a = len(outfield) - n_defenders(len(outfield))
        self.state: dict[int, int] = {
            n: DEFENDING_ATTACKER if i < n_a else DEFENDING_DEFENDER for i, n in enumerate(outfield)
        }
        self.holder: int | None = None
        self.swaps = 0  # role changes so far (a/d pairs)

    def roles(self) -> dict[int, str]:
        out: dict[int, str] = {}
        for n, s in self.state.items():  # a plain loop, `role_name` inline: the team brain asks every step
            out[n] = "attacker" if s in (ATTACKING_ATTACKER, DEFENDING_ATTACKER) else "defender"
        return out

    def apply(self, n: int, inp: str) -> None:
        self.state[n] = transition(self.state[n], inp)

    def send_off(self, n: int) -> None:
        """Robot n has left the field for good: eq. 6 for the outfield robots left. Surplus attackers
        become defenders (input d), the highest-numbered first; missing attackers are the lowest-numbered
        defenders (input a), so static roles keep robots 1..n_a attacking."""
        if n not in self.state:
            return
        del self.state[n]
        if self.holder == n:
            self.holder = None
        left = sorted(self.state)
        n_a = len(left) - n_defenders(len(left))
        attackers = [k for k in left if is_attacker(self.state[k])]
        defenders = [k for k in left if not is_attacker(self.state[k])]
        while len(attackers) > n_a:
            self.apply(attackers.pop(), D)
        while len(attackers) < n_a and defenders:
            k = defenders.pop(0)
            self.apply(k, A)
            attackers.append(k)

    def update(
        self, possession: str, holder: int | None, u: dict[int, float], xy: dict[int, tuple[float, float]]
    ) -> None:
        """One base-station step.

        possession: "own" (a robot of ours holds the ball: input b), "opponent"
        (an opponent has it: input b-bar) or "" (loose ball: no input);
        holder: our robot holding the ball, if any; u: each robot's position
        along the attack direction [m]; xy: positions in the field frame [m].
        """
        if possession in ("own", "opponent"):
            inp = B if possession == "own" else B_BAR
            state = self.state
            for n, s in state.items():  # `apply` inline: every step; a key's value replaced, none added
                state[n] = TRANSITIONS.get((s, inp), s)
        captured = holder is not None and holder != self.holder
        self.holder = holder
        if not self.dynamic or holder is None or holder not in self.state or holder not in u:
            return
        att_lo = self.p.attack[0]
        def_hi = self.p.defense[1]
        attacker = self.state[holder] in (ATTACKING_ATTACKER, DEFENDING_ATTACKER)  # `is_attacker`, inline
        if attacker:
            swap = (captured and u[holder] < def_hi) or u[holder] < att_lo
            out_inp, in_inp = D, A
        else:
            swap = (captured and u[holder] > att_lo) or u[holder] > def_hi
            out_inp, in_inp = A, D
        partners: list[int] = []  # the robots of the other role with a position (a plain loop: no comprehension frames)
        for n, s in self.state.items():  # `is_attacker(s)` inline: a call less per robot
            if (s in (ATTACKING_ATTACKER, DEFENDING_ATTACKER)) is not attacker and n in xy:
                partners.append(n)
        if not swap or not partners or holder not in xy:
            return
        hx, hy = xy[holder]
        partner = min(partners, key=lambda n: (math.hypot(xy[n][0] - hx, xy[n][1] - hy), n))
        self.apply(holder, out_inp)
        self.apply(partner, in_inp)
        self.swaps += 1
