"""--refbox-follow's transition: one real RefBox command -> our referee's state and commands."""

from __future__ import annotations

import pytest

from arena.config import MatchConfig, RefboxParams
from arena.rules import refbox_protocol as rp
from arena.rules.refbox_follow import follow
from arena.rules.referee_box import RefereeState, Rules

CFG = MatchConfig(half_time=10.0)
RULES = Rules.of(CFG)
PARAMS = RefboxParams()
SWAPPED = RefboxParams(swap=True)
PLAYING = RefereeState(stage="FIRST_HALF", command="STOP")
CYAN, MAGENTA = PARAMS.target_cyan, PARAMS.target_magenta


@pytest.mark.parametrize(
    ("command", "params", "name", "team", "spot"),
    [
        (rp.Command("KICKOFF", target=CYAN), PARAMS, "KICKOFF", "a", (0.0, 0.0)),
        (rp.Command("KICKOFF", colour="magenta"), PARAMS, "KICKOFF", "b", (0.0, 0.0)),
        (rp.Command("KICKOFF", target=CYAN), SWAPPED, "KICKOFF", "b", (0.0, 0.0)),
        (rp.Command("CORNER", target=CYAN), PARAMS, "CORNER", "a", (5.75, 3.75)),  # a attacks +x
        (rp.Command("GOALKICK", target=CYAN), PARAMS, "GOALKICK", "a", (-5.5, 1.5)),  # a's own goal line
        (rp.Command("PENALTY", target=MAGENTA), PARAMS, "PENALTY", "b", (-4.0, 0.0)),  # b attacks -x
        (rp.Command("THROWIN", target=MAGENTA), PARAMS, "THROWIN", "b", (1.0, 4.0)),
        (rp.Command("DROP_BALL"), PARAMS, "DROP_BALL", "", (1.0, 2.5)),
        (rp.Command("STOP"), PARAMS, "STOP", "", (0.0, 0.0)),
    ],
)
def test_commands_become_ours_with_their_spots(command, params, name, team, spot):
    st, cmds, why = follow(PLAYING, 50, command, (1.0, 2.5), RULES, params)
    assert not why
    assert [(c.name, c.team, (c.x, c.y), c.tick) for c in cmds] == [(name, team, spot, 50)]
    assert (st.command, st.command_team) == (name, team) or name in ("GOAL",)


def test_start_goal_subgoal_half_time():
    st, _, _ = follow(PLAYING, 5, rp.Command("FREEKICK", target=MAGENTA), (0.0, 0.0), RULES, PARAMS)
    st, (start,), _ = follow(st, 10, rp.Command("START"), (0.0, 0.0), RULES, PARAMS)
    assert (start.name, start.team) == ("START", "b") and st.in_play
    st, (goal,), _ = follow(st, 15, rp.Command("GOAL", target=CYAN), (0.0, 0.0), RULES, PARAMS)
    assert goal.team == "a" and st.score == (1, 0) and st.command == "START"  # GOAL keeps the command in force
    st, none, _ = follow(st, 20, rp.Command("SUBGOAL", target=CYAN), (0.0, 0.0), RULES, PARAMS)
    assert none == [] and st.score == (0, 0)
    st, _, _ = follow(st, 25, rp.Command("HALF_TIME"), (0.0, 0.0), RULES, PARAMS)
    assert st.stage == "HALF_TIME" and st.attack_dir_a == -1


@pytest.mark.parametrize(
    "command",
    [
        rp.Command("TESTMODE_ON"),
        rp.Command("KICKOFF", target="224.0.0.9"),
        rp.Command("SUBGOAL"),
        rp.Command("WELCOME"),
    ],
)
def test_ignored_with_a_reason(command):
    st, cmds, why = follow(PLAYING, 5, command, (0.0, 0.0), RULES, PARAMS)
    assert st == PLAYING and cmds == [] and why


@pytest.mark.parametrize(
    ("command", "name", "team", "robot"),
    [
        (rp.Command("YELLOW_CARD", target=CYAN, robot_id=2), "YELLOW_CARD", "a", 2),
        (rp.Command("RED_CARD", target=MAGENTA, robot_id=0), "RED_CARD", "b", 0),
        (rp.Command("REPAIR", target=MAGENTA, robot_id=1), "REPAIR_OUT", "b", 1),  # the 2020 name of ours
        (rp.Command("GAMEOVER"), "GAMEOVER", "", -1),
    ],
)
def test_cards_repair_and_gameover_are_mirrored_with_the_robot(command, name, team, robot):
    st, cmds, why = follow(PLAYING, 5, command, (0.0, 0.0), RULES, PARAMS)
    assert not why
    assert [(c.name, c.team, c.robot) for c in cmds] == [(name, team, robot)]
    assert st.command == "STOP"  # announcements: the command in force stays


@pytest.mark.parametrize(
    "command",
    [
        rp.Command("YELLOW_CARD", target=CYAN),  # the RefBox's own cards name no robot
        rp.Command("DOUBLE_YELLOW", colour="cyan"),  # nor do the legacy ones
        rp.Command("RED_CARD", target=CYAN, robot_id=CFG.robots),  # not one of ours
    ],
)
def test_a_card_without_a_robot_of_ours_is_ignored_with_a_reason(command):
    st, cmds, why = follow(PLAYING, 5, command, (0.0, 0.0), RULES, PARAMS)
    assert st == PLAYING and cmds == [] and "robotID" in why


def test_bridge_spells_robot_commands_as_the_refbox_does():
    assert rp.encode_json(rp.OUR_TO_WIRE.get("REPAIR_OUT", "REPAIR_OUT"), "t", 2) == (
        b'{"command":"REPAIR","targetTeam":"t","robotID":2}\0'
    )
    assert rp.encode_json("YELLOW_CARD", "t", 1) == b'{"command":"YELLOW_CARD","targetTeam":"t","robotID":1}\0'
    assert rp.encode_json("KICKOFF", "t", 1) == b'{"command":"KICKOFF","targetTeam":"t"}\0'
    assert rp.encode_legacy("DOUBLE_YELLOW", "magenta") == b"b" and rp.encode_legacy("GAMEOVER") == b"z"
