"""Following a human referee: a real RefBox's commands turned into our referee's state.

`arena match --refbox-follow HOST:PORT` (docs/refbox.md): our referee
connects to the official MSL RefBox as a base station would
(`RefboxClient`) and, instead of deciding, applies each command it receives
with `follow`, a pure transition like referee_box.py's `process`. The engine
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
import json
import logging

from arena.rules import refbox_protocol as rp
from arena.rules import setpieces as sp
from arena.rules.refbox_client import RefboxClient
from arena.rules.referee_box import MSL_COMMANDS, TEAM_COMMANDS, RefereeState, Result, Rules, issue
from arena.runtime.config import RefboxParams, RefboxTeam
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


class Follower:
    """Our referee box, driven by a real RefBox instead of its own rules: `step` has the
    signature of `RefereeBox.step`, so the referee process just calls the one it was given."""

    def __init__(self, box, log: logging.Logger, endpoint: str = "", source: str = ""):
        self.box = box  # a RefereeBox: its state, counts and summary stay the match's record
        self.params = box.rules.cfg.refbox
        host, port = rp.parse_endpoint(endpoint or self.params.follow)
        self.endpoint = f"{host}:{port}"
        self.client = RefboxClient(host, port, log, source=source, name="follow")
        self.ball = (0.0, 0.0)
        self.applied = 0
        self.ignored: dict[str, int] = {}
        self.log = log

    def step(self, tick: int, events) -> list:
        for ev in events:  # where the engine last saw the ball: the spot of the next set piece
            self.ball = (ev.x, ev.y)
        out = []
        for cmd in self.client.drain():
            st, cmds, why = follow(self.box.state, tick, cmd, self.ball, self.box.rules, self.params)
            if why:
                self.ignored[why] = self.ignored.get(why, 0) + 1
                self.log.warning("refbox: ignored %s", why)
                continue
            self.box.state = st
            self.applied += 1
            out.extend(cmds)
        end = end_of_match(self.box.state, tick, self.box.rules)
        if end is not None:
            self.box.state, cmds = end
            out.extend(cmds)
        self.box.counts.update(c.name for c in out)
        if tick >= self.box.rules.total_ticks:
            self.client.close()
        return out

    def summary(self) -> dict[str, object]:
        return {
            "endpoint": self.endpoint,
            "connected": self.client.connected.is_set(),  # ever, during the match
            "applied": self.applied,
            "ignored": dict(sorted(self.ignored.items())),
            "errors": len(self.client.errors),
        }


# ------------------------------------------------------------- --via-refbox
VIA_SOURCE = {"a": "127.0.1.1", "b": "127.0.2.1"}  # our base stations' source addresses on loopback
VIA_TEAMS = tuple(
    RefboxTeam(address=ip.rsplit(".", 1)[0] + ".*", name=f"arena {t}", side=t) for t, ip in VIA_SOURCE.items()
)


def via_endpoint(listen: str) -> tuple[str, str]:
    """(endpoint, source address) for our own base station of team `a`/`b` to reach the bridge
    on this machine; the bridge tells the two apart by source address, as the RefBox does."""
    host, port = rp.parse_endpoint(listen)
    if host in ("0.0.0.0", "") or host.startswith("127."):
        return f"tcp/127.0.0.1:{port}", "loopback"
    return f"tcp/{host}:{port}", ""


class ViaRefbox:
    """`--via-refbox`: a base station's referee view from the bridge over TCP, and its
    world model sent back as MSL worldstates (docs/refbox.md)."""

    def __init__(self, cfg, team: str, log: logging.Logger):
        from arena.rules.referee_box import RefereeBox

        endpoint, source = via_endpoint(cfg.refbox.listen)
        self.team = team
        self.dt = cfg.timing.dt
        self.follower = Follower(RefereeBox(cfg), log, endpoint, VIA_SOURCE[team] if source else "")
        self.sent = 0

    def referee(self, k: int, reports: dict):
        """The referee frame of tick k as the commands that came over TCP make it."""
        for r in reports.values():
            if r.ball.visible:
                self.follower.ball = (r.ball.x, r.ball.y)
        return self.follower.box.frame(k, self.follower.step(k, []))

    def send_worldstate(self, k: int, latest: dict) -> None:
        """The newest report of each robot as one worldstate, ageMs from its tick."""
        if not latest:
            return
        oldest = min(r.tick for r in latest.values())
        balls = [r.ball for r in latest.values() if r.ball.visible]
        seen = [(o.x, o.y) for r in latest.values() for o in r.robots if o.team != self.team]
        doc = {
            "type": "worldstate",
            "teamName": f"arena {self.team}",
            "intention": "",
            "ageMs": round((k - oldest) * self.dt * 1000.0),
            "robots": [
                {
                    "id": n,
                    "pose": [r.pose.x, r.pose.y, r.pose.theta],
                    "ballEngaged": int(r.has_ball),
                    "intention": r.role,
                }
                for n, r in sorted(latest.items())
            ],
            "balls": [{"position": [b.x, b.y, 0.0], "confidence": 1.0} for b in balls[:1]],
            "obstacles": [{"position": [x, y], "radius": 0.25, "confidence": 1.0} for x, y in seen],
        }
        if self.follower.client.send(json.dumps(doc, separators=(",", ":")).encode() + b"\0"):
            self.sent += 1

    def close(self) -> None:
        self.follower.client.close()
