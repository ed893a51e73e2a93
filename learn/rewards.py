"""Rewards: what a step was worth to one learner, as a pluggable function.

A reward is any callable `reward(agent, outcome) -> float`; `outcome` is the
`Outcome` of the step for the agent's team. The default, `GoalReward`, gives
+1 for a goal scored and -1 for one conceded, plus `progress` times the metres
the ball moved towards the opponent goal in play during the step, less what a
set piece against took back (0 by default).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from arena.schemas.messages import RefCommand


@dataclass(frozen=True)
class Outcome:
    """One step, seen from one team. Ground truth (the referee's frames and the `world`), never an observation."""

    tick: int  # the decision tick the step ended at
    team: str  # "a" or "b"
    goals_for: int  # goals the team scored during the step
    goals_against: int
    ball_progress: float  # [m] the ball's move towards the team's opponent goal line during the step
    commands: list[RefCommand] = field(default_factory=list)  # the referee's commands issued during the step
    ball_closing: float = 0.0  # [m] how much nearer the ball came to the centre of the opponent goal
    # A scenario's episode, at its last step: whether every expectation came true; None before and without one.
    scenario_passed: bool | None = None
    restarts_for: tuple[str, ...] = ()  # set pieces the referee gave the team during the step (GOALKICK, CORNER, ...)
    restarts_against: tuple[str, ...] = ()  # set pieces it gave the other team: the ball went out off this one, ...
    # [m] the in-play progress since play last started that a restart against ended (>= 0): what the ball
    # gained on its way out, say over the goal line beside the post. GoalReward charges it back.
    progress_lost: float = 0.0

    def fouls_against(self, robot: int) -> int:
        """Cards given to this team's robot `robot` during the step."""
        return sum(1 for c in self.commands if c.team == self.team and c.robot == robot and c.name.endswith("CARD"))


class GoalReward:
    """+1 per goal scored, -1 per goal conceded, + `progress` x (ball progress - progress lost) [m].

    Ball progress counts only while the ball is in play, and what it gained since play last started
    is charged back when the referee gives the other team a set piece (a goal kick when the ball went
    out over the goal line, a throw-in, a corner, a free kick). So pushing the ball out over the goal
    line beside the post earns nothing: only a goal keeps what the ball gained on its way."""

    def __init__(self, progress: float = 0.0):
        self.progress = progress

    def __call__(self, agent: str, o: Outcome) -> float:
        return float(o.goals_for - o.goals_against) + self.progress * (o.ball_progress - o.progress_lost)
