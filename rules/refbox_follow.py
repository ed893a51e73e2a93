"""Following a human referee: a real RefBox's commands turned into our referee's state.

`arena match --refbox-follow HOST:PORT` (docs/refbox.md): our referee
connects to the official MSL RefBox as a base station would (refbox/follow.py
`Follower`, over refbox/client.py) and, instead of deciding, applies each
command it receives with `follow`, a pure transition like referee_box.py's
`process`: this module, with no socket or thread. The engine
keeps placing the ball and reporting ball events; the events no longer decide
anything.

The RefBox protocol carries no ball spot, so the spot of a set piece is
worked out here from the last ball position the engine reported, with the
same placement helpers our own referee uses (setpieces.py): kick-off on the
centre spot; free kick, throw-in and drop ball where the ball was; a corner
on the taker's attacking goal line and a goal kick on its own, on the ball's
side; a penalty on the penalty mark in front of the defenders' goal. START
restarts the command in force for its team. GOAL adds the goal and SUBGOAL
takes one back. Teams come from `targetTeam` (its colour by the configured
targets) or from the legacy letter's case; cyan is team a unless swapped.
Commands our referee has no word for (cards, repairs, test mode, ...) are
ignored and counted; the clock still ends the match (END_GAME at the last
tick) if the RefBox has not.
"""

from __future__ import annotations

import dataclasses

from arena.config import RefboxParams
from arena.rules import refbox_protocol as rp
from arena.rules import setpieces as sp
from arena.rules.referee_box import MSL_COMMANDS, TEAM_COMMANDS, RefereeState, Result, Rules, issue
from arena.schemas.vocabulary import ROBOT_COMMANDS


def team_of_command(cmd: rp.Command, params: RefboxParams) -> str:
    """Our team ("a"/"b") a command is for, or "" (both, or a target we do not know)."""
    colour = cmd.colour
    if not colour and cmd.target:
        colour = {params.target_cyan: "cyan", params.target_magenta: "magenta"}.get(cmd.target, "")
    return rp.team_of(colour, params.swap) if colour else ""


def spot_of(name: str, team: str, st: RefereeState, ball: tuple[float, float], rules: Rules) -> tuple[float, float]:
    cfg = rules.cfg
    bx, by = ball
    half = cfg.field.length / 2
    if name == "KICKOFF":
        return 0.0, 0.0
    if name == "FREEKICK":
        return sp.free_kick_spot(bx, by, cfg)
    if name == "THROWIN":
        return sp.throw_in_spot(bx, by, cfg)
    if name == "DROP_BALL":
        return sp.drop_ball_spot(bx, by, cfg)
    if name == "CORNER":
        return sp.corner_spot(sp.attack_dir(team, st.attack_dir_a) * half, by, cfg)
    if name == "GOALKICK":
        return sp.goal_kick_spot(-sp.attack_dir(team, st.attack_dir_a) * half, by, cfg)
    if name == "PENALTY":
        return sp.attack_dir(team, st.attack_dir_a) * (half - cfg.field.penalty_mark_distance), 0.0
    return 0.0, 0.0


def follow(
    st: RefereeState, tick: int, cmd: rp.Command, ball: tuple[float, float], rules: Rules, params: RefboxParams
) -> tuple[RefereeState, list, str]:
    """(new state, our commands, why ignored or "") for one command of the real RefBox."""
    name = rp.WIRE_TO_OURS.get(cmd.name, cmd.name)
    team = team_of_command(cmd, params)
    if name == "SUBGOAL":
        if team not in ("a", "b"):
            return st, [], "SUBGOAL without a known team"
        a, b = st.score
        return dataclasses.replace(st, score=(max(0, a - 1), b) if team == "a" else (a, max(0, b - 1))), [], ""
    if name not in MSL_COMMANDS:
        return st, [], f"{name} is not a command of our referee"
    if name in TEAM_COMMANDS and not team:
        return st, [], f"{name} for unknown targetTeam {cmd.target!r}"
    if name in ROBOT_COMMANDS:  # the RefBox's cards carry no robotID: we cannot tell whom to send off
        if not 0 <= cmd.robot_id < rules.cfg.robots:
            return st, [], f"{name} without a robotID of ours"
        st, c = issue(st, tick, name, team, (0.0, 0.0), cmd.robot_id)
        return st, [c], ""
    if name == "START":
        st, c = issue(st, tick, "START", st.command_team, st.spot)
        return st, [c], ""
    if name == "GOAL":
        a, b = st.score
        st = dataclasses.replace(st, score=(a + 1, b) if team == "a" else (a, b + 1))
    if name == "HALF_TIME" and st.stage == "FIRST_HALF":
        st = dataclasses.replace(st, attack_dir_a=-st.attack_dir_a)  # the teams change ends, as in our referee
    team = team if name in TEAM_COMMANDS else ""
    st, c = issue(st, tick, name, team, spot_of(name, team, st, ball, rules) if name in sp.SET_PIECES else (0.0, 0.0))
    return st, [c], ""


def end_of_match(st: RefereeState, tick: int, rules: Rules) -> Result | None:
    """END_GAME at the last tick when the RefBox has not ended the game."""
    if tick < rules.total_ticks or st.stage == "END_GAME":
        return None
    st, c = issue(st, tick, "END_GAME")
    return st, [c]
