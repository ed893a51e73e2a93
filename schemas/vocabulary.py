"""The words every layer shares, defined once: teams, the MSL RefBox command and
stage names, and the set pieces.

They live here, in the bottom layer, because schemas/messages.py types its
fields with them (a referee frame with an unknown command name fails to decode
and is counted as malformed), and nothing in schemas/ may import a layer above.
`arena.rules` re-exports the referee's words, so that rule code reads them
from the package of its concern.
"""

from __future__ import annotations

from typing import Literal, get_args

Team = Literal["a", "b"]
TeamOrNone = Literal["a", "b", ""]  # "" = both teams, or nobody
TEAMS: tuple[Team, Team] = ("a", "b")

SetPieceName = Literal["KICKOFF", "FREEKICK", "GOALKICK", "THROWIN", "CORNER", "PENALTY", "DROP_BALL"]
RefCommandName = Literal[
    "START",
    "STOP",
    "KICKOFF",
    "FREEKICK",
    "GOALKICK",
    "THROWIN",
    "CORNER",
    "PENALTY",
    "DROP_BALL",
    "GOAL",
    "FIRST_HALF",
    "HALF_TIME",
    "SECOND_HALF",
    "END_GAME",
    "PARK",
    "GAMEOVER",
    "YELLOW_CARD",
    "RED_CARD",
    "DOUBLE_YELLOW",
    "REPAIR_OUT",
]
StageName = Literal["PRE_GAME", "FIRST_HALF", "HALF_TIME", "SECOND_HALF", "END_GAME"]

SET_PIECES: frozenset[str] = frozenset(get_args(SetPieceName))
REF_COMMANDS: frozenset[str] = frozenset(get_args(RefCommandName))
STAGES: tuple[StageName, ...] = get_args(StageName)
# Restarts after a stoppage: every set piece but the kick-off (which starts a half or follows a goal).
RESTARTS: tuple[SetPieceName, ...] = tuple(s for s in get_args(SetPieceName) if s != "KICKOFF")

# Commands about one robot: they carry its team and number (RefCommand.robot).
CARDS: frozenset[str] = frozenset({"YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW"})
SEND_OFF: frozenset[str] = frozenset({"RED_CARD", "DOUBLE_YELLOW", "REPAIR_OUT"})  # the robot leaves the field
ROBOT_COMMANDS: frozenset[str] = CARDS | {"REPAIR_OUT"}

assert set(SET_PIECES) <= REF_COMMANDS and ROBOT_COMMANDS <= REF_COMMANDS


def other_team(team: str) -> Team:
    """The opponent of `team` ("a" <-> "b")."""
    return "b" if team == "a" else "a"
