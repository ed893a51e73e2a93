"""The referee box: a pure state machine over typed changes, with an append-only log.

Modelled on ssl-game-controller: ``process(state, change, rules) ->
(new_state, commands)`` never mutates its input; a change is either the clock
(`Clock(tick)`) or a ball-status event of the engine (`Observed(tick,
BallEvent)`, G_Re). `RefereeBox` holds the current state, feeds it the
changes of one referee period (the events first, then the clock) and appends
every change that did something to `log` with the state before and after it.
Commands are MSL RefBox commands (`MSL_COMMANDS`), each with its target team
and ball spot. The rules, one small function each, and their parameters are
tabled in docs/rules.md:

* clock rules (`CLOCK_RULES`, the first that applies fires): END_GAME on the
  last tick; FIRST_HALF and KICKOFF for team a out of PRE_GAME; at half time
  HALF_TIME, the teams change ends (`attack_dir_a` flips), SECOND_HALF and
  KICKOFF for team b; START when the positioning time is over; and STOP plus
  DROP_BALL when a set piece was not taken within `take_time` of its START.
* event rules (`EVENT_RULES`, by event kind; only while the ball is in play,
  i.e. the command in force is START and the event happened after it):
  GOAL -> GOAL (scorer), KICKOFF for the conceding team; TOUCH_LINE ->
  THROWIN for the other team than the last toucher's; GOAL_LINE -> CORNER
  if the defending team touched it last, else GOALKICK; NO_PROGRESS ->
  DROP_BALL; FOUL_PUSHING and FOUL_DRIBBLING -> FREEKICK for the other team
  than the offender's, or PENALTY at the penalty mark if a defender fouled in
  its own penalty area. A TOUCH after START marks the set piece as taken.
* discipline: every foul counts against the robot that committed it; its
  `yellow_fouls`-th foul adds YELLOW_CARD, its 2 x `yellow_fouls`-th
  DOUBLE_YELLOW, its `red_fouls`-th (if set) RED_CARD, between the STOP and
  the restart. ROBOT_DEAD and ROBOT_STUCK (at any time) give REPAIR_OUT. DOUBLE_YELLOW,
  RED_CARD and REPAIR_OUT send the robot off (`off`); the engine parks it.
* END_GAME is followed on the same tick by PARK and GAMEOVER.

Every restart is the MSL set-piece procedure: STOP, then the command with
its team and ball spot (`setpieces.py`), then after the positioning time
START for the same team. Time is the tick it is handed; nothing here reads a
clock or draws a random number."""

from __future__ import annotations

import dataclasses
import math
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

from arena.config import TEAMS, MatchConfig
from arena.rules import setpieces as sp
from arena.schemas.messages import BallEvent, RefCommand, Referee, RefereeOverride
from arena.schemas.vocabulary import REF_COMMANDS, ROBOT_COMMANDS, SEND_OFF, SET_PIECES, STAGES, other_team

MSL_COMMANDS = REF_COMMANDS  # arena.schemas.vocabulary.RefCommandName: the wire types check them on decode
TEAM_COMMANDS = (SET_PIECES - {"DROP_BALL"}) | {"GOAL"} | ROBOT_COMMANDS  # need a team
PLAYING_STAGES = frozenset({"FIRST_HALF", "SECOND_HALF"})
_STAGE_COMMANDS = frozenset({"FIRST_HALF", "HALF_TIME", "SECOND_HALF", "END_GAME"})
# announced; the command in force stays
_KEEP_IN_FORCE = frozenset({"GOAL", "FIRST_HALF", "SECOND_HALF", "PARK", "GAMEOVER"}) | ROBOT_COMMANDS
FOULS = frozenset({"FOUL_PUSHING", "FOUL_DRIBBLING"})


def check_referee(frame: Referee) -> str | None:
    """Reject referee frames no referee box could have sent (Inbound `check=`).

    Stages and command names must be the MSL RefBox's, a team "a", "b" or ""
    (both), and a command that needs a target team must have one.
    """
    if frame.stage not in STAGES:
        return f"unknown stage {frame.stage!r}"
    if frame.command not in MSL_COMMANDS:
        return f"unknown command {frame.command!r}"
    if frame.command_team not in ("a", "b", ""):
        return f"unknown team {frame.command_team!r}"
    if frame.attack_dir_a not in (1, -1):
        return f"attack_dir_a {frame.attack_dir_a} (expected 1 or -1)"
    if not (math.isfinite(frame.spot_x) and math.isfinite(frame.spot_y)):
        return "spot is not finite"
    for c in frame.commands:
        if c.name not in MSL_COMMANDS:
            return f"unknown command {c.name!r}"
        if c.team not in ("a", "b", ""):
            return f"{c.name} for unknown team {c.team!r}"
        if c.name in TEAM_COMMANDS and not c.team:
            return f"{c.name} without a target team"
        if not (math.isfinite(c.x) and math.isfinite(c.y)):
            return f"{c.name} spot is not finite"
        if (c.name in ROBOT_COMMANDS) != (c.robot >= 0):
            return f"{c.name} with robot {c.robot}" if c.robot >= 0 else f"{c.name} without a robot"
    return None


# --------------------------------------------------------------------- state
@dataclass(frozen=True)
class RefereeState:
    """What the referee box holds in force: the stage, the command with its team and spot, the score, fouls,
    robots sent off, and the ticks that bound the restart."""

    stage: str = "PRE_GAME"
    command: str = "STOP"  # the command in force
    command_team: str = ""
    spot: tuple[float, float] = (0.0, 0.0)  # [m] ball spot of the command in force
    score: tuple[int, int] = (0, 0)  # goals of team a, team b
    attack_dir_a: int = 1  # +1: team a attacks the +x goal
    issued_at: int = 0  # tick the command in force was issued; older events are stale
    start_at: int = -1  # tick at which START is due, -1 for none
    take_by: int = -1  # tick by which the set piece must be taken, -1 for none
    fouls: tuple[tuple[str, int, int], ...] = ()  # (team, robot, fouls so far), sorted
    off: tuple[tuple[str, int], ...] = ()  # robots sent off (cards, REPAIR_OUT), in order

    @property
    def in_play(self) -> bool:
        return self.command == "START" and self.stage in PLAYING_STAGES


@dataclass(frozen=True)
class Clock:
    """Time has come to `tick`."""

    tick: int


@dataclass(frozen=True)
class Forced:
    """A scenario's step, or a live session's operator, forces `override` at `tick` (sim/director.py)."""

    tick: int
    override: RefereeOverride
    by: str = "scenario"  # or "operator"


@dataclass(frozen=True)
class Observed:
    """The engine reported `event`; the referee handles it at its tick `tick`."""

    tick: int
    event: BallEvent


Change = Clock | Observed | Forced


@dataclass(frozen=True)
class Rules:
    """The configuration the rules need, with times in ticks."""

    cfg: MatchConfig
    half_ticks: int
    total_ticks: int
    kickoff_ticks: int
    setpiece_ticks: int
    take_ticks: int

    @classmethod
    def of(cls, cfg: MatchConfig) -> Rules:
        dt, r = cfg.timing.dt, cfg.rules
        return cls(
            cfg=cfg,
            half_ticks=cfg.half_ticks - cfg.scenario.clock,  # a scenario may start with time already played
            total_ticks=cfg.total_ticks,
            kickoff_ticks=int(round(r.kickoff_time / dt)),
            setpiece_ticks=int(round(r.setpiece_time / dt)),
            take_ticks=int(round(r.take_time / dt)),
        )


@dataclass(frozen=True)
class Restart:
    """What an event rule decides: a set piece, after a goal for `goal` if set."""

    command: str
    team: str
    spot: tuple[float, float]
    goal: str = ""


Result = tuple[RefereeState, list[RefCommand]]


# ------------------------------------------------------------------ commands
def issue(
    st: RefereeState, tick: int, name: str, team: str = "", spot=(0.0, 0.0), robot: int = -1
) -> tuple[RefereeState, RefCommand]:
    """The state after announcing `name`, and the command itself."""
    cmd = RefCommand(name=name, team=team, x=spot[0], y=spot[1], tick=tick, robot=robot)
    if name in _STAGE_COMMANDS:
        st = dataclasses.replace(st, stage=name)
    if name not in _KEEP_IN_FORCE:
        st = dataclasses.replace(st, command=name, command_team=team, spot=spot, issued_at=tick)
    return st, cmd


def restart(st: RefereeState, tick: int, r: Restart, rules: Rules, cards: tuple[RefCommand, ...] = ()) -> Result:
    """STOP, any cards, the set-piece command, and START due after the positioning time."""
    out = []
    if r.goal:
        a, b = st.score
        st = dataclasses.replace(st, score=(a + 1, b) if r.goal == "a" else (a, b + 1))
        st, c = issue(st, tick, "GOAL", r.goal, r.spot)
        out.append(c)
    st, c = issue(st, tick, "STOP")
    out.append(c)
    out.extend(cards)
    st, c = issue(st, tick, r.command, r.team, r.spot)
    out.append(c)
    wait = rules.kickoff_ticks if r.command == "KICKOFF" else rules.setpiece_ticks
    return dataclasses.replace(st, start_at=tick + wait, take_by=-1), out


# --------------------------------------------------------------- event rules
def goal_rule(st: RefereeState, ev: BallEvent, rules: Rules) -> Restart | None:
    """GOAL: the scorer's goal counts; the conceding team kicks off."""
    if ev.team not in TEAMS:
        return None
    return Restart("KICKOFF", other_team(ev.team), (0.0, 0.0), goal=ev.team)


def touch_line_rule(st: RefereeState, ev: BallEvent, rules: Rules) -> Restart | None:
    """TOUCH_LINE: throw-in for the other team than the last toucher's (nobody touched: drop ball)."""
    if ev.last_team not in TEAMS:
        return Restart("DROP_BALL", "", sp.drop_ball_spot(ev.x, ev.y, rules.cfg))
    return Restart("THROWIN", other_team(ev.last_team), sp.throw_in_spot(ev.x, ev.y, rules.cfg))


def goal_line_rule(st: RefereeState, ev: BallEvent, rules: Rules) -> Restart | None:
    """GOAL_LINE: corner if the defending team (`ev.team`) touched it last, else goal kick."""
    defender = ev.team if ev.team in TEAMS else sp.defender_of_goal_line(ev.x, st.attack_dir_a)
    if ev.last_team == defender:
        return Restart("CORNER", other_team(defender), sp.corner_spot(ev.x, ev.y, rules.cfg))
    return Restart("GOALKICK", defender, sp.goal_kick_spot(ev.x, ev.y, rules.cfg))


def no_progress_rule(st: RefereeState, ev: BallEvent, rules: Rules) -> Restart | None:
    """NO_PROGRESS: drop ball where the ball lies, kept inside the lines."""
    return Restart("DROP_BALL", "", sp.drop_ball_spot(ev.x, ev.y, rules.cfg))


def foul_rule(st: RefereeState, ev: BallEvent, rules: Rules) -> Restart | None:
    """FOUL_PUSHING, FOUL_DRIBBLING: free kick for the other team where the foul happened;
    a penalty if the offender was defending its own penalty area."""
    if ev.team not in TEAMS:
        return None
    if sp.in_own_penalty_area(ev.team, ev.x, ev.y, st.attack_dir_a, rules.cfg):
        return Restart("PENALTY", other_team(ev.team), sp.penalty_spot(ev.team, st.attack_dir_a, rules.cfg))
    return Restart("FREEKICK", other_team(ev.team), sp.free_kick_spot(ev.x, ev.y, rules.cfg))


def card_rule(fouls: int, rules: Rules) -> str | None:
    """The card a robot's `fouls`-th foul earns (RulesParams.yellow_fouls, red_fouls), if any."""
    p = rules.cfg.rules
    if p.red_fouls > 0 and fouls == p.red_fouls:
        return "RED_CARD"
    if p.yellow_fouls > 0 and fouls == 2 * p.yellow_fouls:
        return "DOUBLE_YELLOW"
    if p.yellow_fouls > 0 and fouls == p.yellow_fouls:
        return "YELLOW_CARD"
    return None


def book(st: RefereeState, tick: int, ev: BallEvent, rules: Rules) -> tuple[RefereeState, tuple[RefCommand, ...]]:
    """Count a foul against its robot; the card it earns, if any (a red or a double yellow sends it off)."""
    if ev.team not in TEAMS or ev.robot < 0:
        return st, ()
    counts = {(t, n): k for t, n, k in st.fouls}
    k = counts.get((ev.team, ev.robot), 0) + 1
    counts[(ev.team, ev.robot)] = k
    st = dataclasses.replace(st, fouls=tuple(sorted((t, n, c) for (t, n), c in counts.items())))
    card = card_rule(k, rules)
    if card is None:
        return st, ()
    return send_off(*issue(st, tick, card, ev.team, (ev.x, ev.y), ev.robot))


def send_off(st: RefereeState, c: RefCommand) -> tuple[RefereeState, tuple[RefCommand, ...]]:
    if c.name in SEND_OFF and (c.team, c.robot) not in st.off:
        st = dataclasses.replace(st, off=(*st.off, (c.team, c.robot)))
    return st, (c,)


def repair_out_rule(st: RefereeState, tick: int, ev: BallEvent, rules: Rules) -> Result:
    """ROBOT_DEAD, ROBOT_STUCK: REPAIR_OUT for it, once, whether the ball is in play or not; play goes on."""
    if ev.team not in TEAMS or ev.robot < 0 or (ev.team, ev.robot) in st.off:
        return st, []
    st, cards = send_off(*issue(st, tick, "REPAIR_OUT", ev.team, (0.0, 0.0), ev.robot))
    return st, list(cards)


EventRule = Callable[[RefereeState, BallEvent, Rules], Restart | None]
EVENT_RULES: dict[str, EventRule] = {
    "GOAL": goal_rule,
    "TOUCH_LINE": touch_line_rule,
    "GOAL_LINE": goal_line_rule,
    "NO_PROGRESS": no_progress_rule,
    "FOUL_PUSHING": foul_rule,
    "FOUL_DRIBBLING": foul_rule,
}


def on_event(st: RefereeState, tick: int, ev: BallEvent, rules: Rules) -> Result:
    if ev.kind in ("ROBOT_DEAD", "ROBOT_STUCK"):
        return repair_out_rule(st, tick, ev, rules) if st.stage != "END_GAME" else (st, [])
    if not st.in_play or ev.tick <= st.issued_at:
        return st, []  # stopped, or it happened before START: stale
    if ev.kind == "TOUCH":
        return (dataclasses.replace(st, take_by=-1) if st.take_by >= 0 else st), []
    rule = EVENT_RULES.get(ev.kind)
    decision = rule(st, ev, rules) if rule else None
    if decision is None:
        return st, []
    st, cards = book(st, tick, ev, rules) if ev.kind in FOULS else (st, ())
    return restart(st, tick, decision, rules, cards)


# --------------------------------------------------------------- clock rules
def end_game(st: RefereeState, tick: int, rules: Rules) -> Result | None:
    if tick < rules.total_ticks:
        return None
    st, c = issue(st, tick, "END_GAME")
    st, p = issue(st, tick, "PARK")
    st, g = issue(st, tick, "GAMEOVER")
    return dataclasses.replace(st, start_at=-1, take_by=-1), [c, p, g]


def first_half(st: RefereeState, tick: int, rules: Rules) -> Result | None:
    if st.stage != "PRE_GAME":
        return None
    st, c = issue(st, tick, "FIRST_HALF")
    st, k = issue(st, tick, "KICKOFF", "a", (0.0, 0.0))
    return dataclasses.replace(st, start_at=tick + rules.kickoff_ticks, take_by=-1), [c, k]


def half_time(st: RefereeState, tick: int, rules: Rules) -> Result | None:
    """Half time: the teams change ends; the team that did not kick off first does now."""
    if st.stage != "FIRST_HALF" or tick < rules.half_ticks:
        return None
    st, h = issue(st, tick, "HALF_TIME")
    st = dataclasses.replace(st, attack_dir_a=-st.attack_dir_a)
    st, s = issue(st, tick, "SECOND_HALF")
    st, k = issue(st, tick, "KICKOFF", "b", (0.0, 0.0))
    return dataclasses.replace(st, start_at=tick + rules.kickoff_ticks, take_by=-1), [h, s, k]


def positioning_over(st: RefereeState, tick: int, rules: Rules) -> Result | None:
    """START for the set piece's team; a set piece other than a drop ball must then be taken."""
    if st.start_at < 0 or tick < st.start_at or st.stage not in PLAYING_STAGES:
        return None
    taken_by = tick + rules.take_ticks if st.command in sp.SET_PIECES - {"DROP_BALL"} else -1
    st, c = issue(st, tick, "START", st.command_team, st.spot)
    return dataclasses.replace(st, start_at=-1, take_by=taken_by), [c]


def set_piece_not_taken(st: RefereeState, tick: int, rules: Rules) -> Result | None:
    if not st.in_play or st.take_by < 0 or tick < st.take_by:
        return None
    return restart(st, tick, Restart("DROP_BALL", "", st.spot), rules)


ClockRule = Callable[[RefereeState, int, Rules], Result | None]
CLOCK_RULES: tuple[ClockRule, ...] = (end_game, first_half, half_time, positioning_over, set_piece_not_taken)


def clock_due(st: RefereeState, rules: Rules) -> float:
    """A tick before which no clock rule fires in `st` (`on_clock` returns it unchanged with no command):
    at once out of PRE_GAME, never after END_GAME, else the earliest of the last tick, half time in the
    first half, and the state's start_at and take_by (each rule above tests its own tick against one of them)."""
    if st.stage == "END_GAME":
        return math.inf
    if st.stage == "PRE_GAME":
        return 0
    due = rules.total_ticks
    if st.stage == "FIRST_HALF" and rules.half_ticks < due:
        due = rules.half_ticks
    if 0 <= st.start_at < due:
        due = st.start_at
    if 0 <= st.take_by < due:
        due = st.take_by
    return due


def on_clock(st: RefereeState, tick: int, rules: Rules) -> Result:
    if st.stage == "END_GAME":
        return st, []
    for rule in CLOCK_RULES:
        result = rule(st, tick, rules)
        if result is not None:
            return result
    return st, []


# ------------------------------------------------------------------ overrides
def override_spot(o: RefereeOverride, st: RefereeState, cfg: MatchConfig) -> tuple[float, float]:
    """The ball spot of a forced command: its own, else the rule's spot that needs no ball position
    (the centre for a kick-off, the mark for a penalty, the left corner or the goal area's centre
    of the end the command's team attacks or defends); (0, 0) for the rest."""
    if o.x is not None and o.y is not None:
        return o.x, o.y
    f = cfg.field
    if o.command == "PENALTY" and o.team in TEAMS:
        return sp.penalty_spot(other_team(o.team), st.attack_dir_a, cfg)
    if o.command == "CORNER" and o.team in TEAMS:
        return sp.corner_spot(sp.attack_dir(o.team, st.attack_dir_a) * f.length / 2, f.width / 2, cfg)
    if o.command == "GOALKICK" and o.team in TEAMS:
        return sp.goal_kick_spot(-sp.attack_dir(o.team, st.attack_dir_a) * f.length / 2, 0.0, cfg)
    return 0.0, 0.0


def forced(st: RefereeState, tick: int, o: RefereeOverride, rules: Rules) -> Result:
    """A scenario's decision, taken as the box takes its own: a set piece is the MSL procedure (STOP,
    the command, START after the positioning time), GOAL counts and the other team kicks off, a
    card or REPAIR_OUT books or sends off its robot, HALF_TIME and END_GAME run their rules."""
    spot = override_spot(o, st, rules.cfg)
    if o.command in sp.SET_PIECES:
        return restart(st, tick, Restart(o.command, o.team, spot), rules)
    if o.command == "GOAL" and o.team in TEAMS:
        return restart(st, tick, Restart("KICKOFF", other_team(o.team), (0.0, 0.0), goal=o.team), rules)
    if o.command in ROBOT_COMMANDS:
        st, cards = send_off(*issue(st, tick, o.command, o.team, spot, o.robot))
        return st, list(cards)
    if o.command == "HALF_TIME":
        now = dataclasses.replace(rules, half_ticks=tick)
        return half_time(dataclasses.replace(st, stage="FIRST_HALF"), tick, now) or (st, [])
    if o.command == "END_GAME":
        return end_game(st, tick, dataclasses.replace(rules, total_ticks=tick)) or (st, [])
    st, c = issue(st, tick, o.command, o.team, spot)
    return dataclasses.replace(st, start_at=-1, take_by=-1), [c]


def process(state: RefereeState, change: Change, rules: Rules) -> Result:
    """The pure transition: the state after `change`, and the commands it issues."""
    match change:
        case Clock(tick=tick):
            return on_clock(state, tick, rules)
        case Observed(tick=tick, event=ev):
            return on_event(state, tick, ev, rules)
        case Forced(tick=tick, override=o):
            return forced(state, tick, o, rules)
    raise TypeError(f"not a referee change: {change!r}")


# ------------------------------------------------------------------- the box
@dataclass(frozen=True)
class LogEntry:
    """One change the box made: its id, tick, the change and the states before and after."""

    id: int
    tick: int
    change: Change
    state_pre: RefereeState
    state: RefereeState
    commands: tuple[RefCommand, ...]

    @property
    def cause(self) -> str:
        match self.change:
            case Observed(event=ev):
                who = f" {ev.team}/{ev.robot}" if ev.robot >= 0 else (f" {ev.team}" if ev.team else "")
                return f"{ev.kind.lower()}{who}"
            case Forced(by=by):
                return by
            case _:
                return "clock"


class RefereeBox:
    """The current state and the log; `step` feeds one referee period's changes through `process`."""

    def __init__(self, cfg: MatchConfig):
        self.rules = Rules.of(cfg)
        sc = cfg.scenario  # a scenario may start in a half, with a score
        self.state = (
            RefereeState(stage=sc.stage, score=sc.score, attack_dir_a=sc.attack_dir_a) if sc.stage else RefereeState()
        )
        self.log: list[LogEntry] = []
        self.counts: Counter[str] = Counter()
        self._due_of: RefereeState | None = None  # the state `_due` is `clock_due` of
        self._due: float = 0

    def step(
        self,
        tick: int,
        events: list[BallEvent],
        forced: tuple[RefereeOverride, ...] = (),
        operator: tuple[RefereeOverride, ...] = (),
    ) -> list[RefCommand]:
        """The commands of referee tick `tick`: a scenario's and an operator's forced ones, the engine's
        events, then the clock."""
        if not events and not forced and not operator:
            # most referee ticks: no event, and no clock rule due in the state in force (it changes
            # rarely; a follower may set it too, hence the identity test): nothing changes
            st = self.state
            if st is not self._due_of:
                self._due_of, self._due = st, clock_due(st, self.rules)
            if tick < self._due:
                return []
        out: list[RefCommand] = []
        # plain loops, no generators: most referee ticks have no forced change and no event
        changes: list[Change] = []
        for o in forced:
            changes.append(Forced(tick, o))
        for o in operator:
            changes.append(Forced(tick, o, "operator"))
        for ev in events:
            changes.append(Observed(tick, ev))
        changes.append(Clock(tick))
        for change in changes:
            pre = self.state
            state, cmds = process(pre, change, self.rules)
            if not cmds and (state is pre or state == pre):  # the same state: no field compared
                continue
            self.state = state
            self.log.append(LogEntry(len(self.log), tick, change, pre, state, tuple(cmds)))
            self.counts.update(c.name for c in cmds)
            out.extend(cmds)
        return out

    def frame(self, tick: int, commands: list[RefCommand]) -> Referee:
        """The `referee` message for tick `tick` (Re_G and to the base stations)."""
        st = self.state
        (x, y), (a, b) = st.spot, st.score
        # tick, stage, command, command_team, spot_x, spot_y, score_a, score_b, attack_dir_a, commands:
        # positional, in the fields' order (a keyword costs msgspec a name lookup)
        return Referee(tick, st.stage, st.command, st.command_team, x, y, a, b, st.attack_dir_a, commands)

    def summary(self) -> dict[str, object]:
        """Score, command counts and one log line per command, for the match summary."""
        return {
            "score": list(self.state.score),
            "events": dict(self.counts),
            "log": [
                {"tick": e.tick, "command": c.name, "team": c.team, "cause": e.cause}
                | ({"robot": c.robot} if c.robot >= 0 else {})
                for e in self.log
                for c in e.commands
            ],
        }
