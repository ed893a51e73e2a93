"""Rewards: what a step was worth to one learner, as a pluggable function.

A reward is any callable `reward(agent, outcome) -> float`; `outcome` is the
`Outcome` of the step for the agent's team. The default, `GoalReward`, gives
+1 for a goal scored and -1 for one conceded, plus `progress` times the metres
the ball moved towards the opponent goal during the step (0 by default).
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

    def fouls_against(self, robot: int) -> int:
        """Cards given to this team's robot `robot` during the step."""
        return sum(1 for c in self.commands if c.team == self.team and c.robot == robot and c.name.endswith("CARD"))


class GoalReward:
    """+1 per goal scored, -1 per goal conceded, + `progress` x ball progress [m]."""

    def __init__(self, progress: float = 0.0):
        self.progress = progress

    def __call__(self, agent: str, o: Outcome) -> float:
        return float(o.goals_for - o.goals_against) + self.progress * o.ball_progress
