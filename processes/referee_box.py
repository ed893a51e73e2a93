"""The referee box as a pure state machine with an append-only event log.

``RefereeBox.step(tick, events) -> commands``: time is the tick it is handed,
inputs are the engine's typed ball events (G_Re). It owns the stage, the score
and the sides, and issues MSL RefBox commands with their target team.

The match flow implemented here:

* tick 0: FIRST_HALF, KICKOFF for team a, START after `kickoff_wait`;
* GOAL event while the ball is in play: GOAL (scoring team), STOP, KICKOFF for
  the conceding team, START after `kickoff_wait`;
* ball over a touch line or goal line, or no progress for the engine's idle
  time: STOP, DROP_BALL at the nearest spot 1 m inside the lines, START after
  `restart_wait` (throw-ins, goal kicks and corners come with the rules work);
* half time: HALF_TIME, the teams change ends, SECOND_HALF, KICKOFF for team b,
  START after `kickoff_wait`;
* the last tick: END_GAME.

Every command is appended to `log` together with the stage and score before
and after it, like ssl-game-controller's event log.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

from arena.runtime.config import MatchConfig
from arena.schemas.messages import BallEvent, RefCommand


@dataclass
class LogEntry:
    tick: int
    command: RefCommand
    stage_before: str
    stage_after: str
    score: tuple[int, int]
    cause: str


@dataclass
class RefereeState:
    stage: str = "PRE_GAME"
    command: str = "STOP"
    command_team: str = ""
    spot: tuple[float, float] = (0.0, 0.0)
    score: dict[str, int] = field(default_factory=lambda: {"a": 0, "b": 0})
    attack_dir_a: int = 1  # +1: team a attacks the +x goal
    start_at: int = -1  # tick at which START is due, -1 for none


class RefereeBox:
    def __init__(self, cfg: MatchConfig, kickoff_wait: float = 1.0, restart_wait: float = 1.0):
        self.cfg = cfg
        self.half_ticks = cfg.half_ticks
        self.total_ticks = cfg.total_ticks
        self.kickoff_wait = int(round(kickoff_wait / cfg.timing.dt))  # [ticks]
        self.restart_wait = int(round(restart_wait / cfg.timing.dt))  # [ticks]
        self.state = RefereeState()
        self.log: list[LogEntry] = []
        self.counts: Counter[str] = Counter()

    # ---------------------------------------------------------------- helpers
    def _issue(self, out: list[RefCommand], tick: int, name: str, team: str = "", spot=(0.0, 0.0), cause: str = "") -> None:
        st = self.state
        before = st.stage
        cmd = RefCommand(name=name, team=team, x=spot[0], y=spot[1], tick=tick)
        if name in ("FIRST_HALF", "HALF_TIME", "SECOND_HALF", "END_GAME"):
            st.stage = name
        if name not in ("GOAL", "FIRST_HALF", "SECOND_HALF"):
            st.command, st.command_team, st.spot = name, team, spot
        out.append(cmd)
        self.counts[name] += 1
        self.log.append(LogEntry(tick, cmd, before, st.stage, (st.score["a"], st.score["b"]), cause))

    def _kickoff(self, out: list[RefCommand], tick: int, team: str, cause: str) -> None:
        self._issue(out, tick, "KICKOFF", team, (0.0, 0.0), cause)
        self.state.start_at = tick + self.kickoff_wait

    def _inside_spot(self, x: float, y: float) -> tuple[float, float]:
        hx = self.cfg.field.length / 2.0 - 1.0
        hy = self.cfg.field.width / 2.0 - 1.0
        return (max(-hx, min(hx, x)), max(-hy, min(hy, y)))

    @property
    def in_play(self) -> bool:
        return self.state.command == "START" and self.state.stage in ("FIRST_HALF", "SECOND_HALF")

    # ------------------------------------------------------------------- step
    def step(self, tick: int, events: list[BallEvent]) -> list[RefCommand]:
        st = self.state
        out: list[RefCommand] = []
        if st.stage == "END_GAME":
            return out
        if tick >= self.total_ticks:
            self._issue(out, tick, "END_GAME", cause="time")
            st.start_at = -1
            return out
        if st.stage == "PRE_GAME":
            self._issue(out, tick, "FIRST_HALF", cause="start")
            self._kickoff(out, tick, "a", "first half")
            return out
        if st.stage == "FIRST_HALF" and tick >= self.half_ticks:
            self._issue(out, tick, "HALF_TIME", cause="time")
            st.attack_dir_a = -st.attack_dir_a
            self._issue(out, tick, "SECOND_HALF", cause="sides switched")
            self._kickoff(out, tick, "b", "second half")
            return out
        for ev in events:
            if not self.in_play:
                break
            if ev.kind == "GOAL" and ev.team in ("a", "b"):
                st.score[ev.team] += 1
                self._issue(out, tick, "GOAL", ev.team, (ev.x, ev.y), cause=f"goal by {ev.team}")
                self._issue(out, tick, "STOP", cause="goal")
                self._kickoff(out, tick, "b" if ev.team == "a" else "a", "after goal")
            elif ev.kind in ("TOUCH_LINE", "GOAL_LINE", "NO_PROGRESS"):
                self._issue(out, tick, "STOP", cause=ev.kind.lower())
                self._issue(out, tick, "DROP_BALL", "", self._inside_spot(ev.x, ev.y), cause=ev.kind.lower())
                st.start_at = tick + self.restart_wait
        if st.start_at >= 0 and tick >= st.start_at and not out:
            self._issue(out, tick, "START", st.command_team, st.spot, cause="positioning time over")
            st.start_at = -1
        return out
