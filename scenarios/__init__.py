"""Scenarios: test a team's code like software (docs/scenarios.md).

A scenario file (`*.scenario.toml`) says what plays, how the match stands at
tick 0, the steps on the way (teleports, referee commands) and the
expectations that must come true. The stable API:

* `load(path, name="") -> Scenario`, `load_all(path) -> list[Scenario]`:
  read and validate (a bad file raises `ScenarioError`, one line);
* `Scenario.config(seed, base=None) -> MatchConfig`: the match that plays it;
  its `scenario` field carries the start and the steps, which the engine and
  the referee apply at their ticks (sim/director.py), on either engine;
* `run_one(scenario, seed, engine) -> Verdict`: play and judge one run.

May import arena.match, arena.experiments (its benchmark's table) and every package
below them; imported by learn (a scenario's reset) and the CLI.
"""

from arena.scenarios.model import Scenario, ScenarioError, discover, load, load_all
from arena.scenarios.runner import Outcome, Verdict, run_one, wilson

__all__ = ["Outcome", "Scenario", "ScenarioError", "Verdict", "discover", "load", "load_all", "run_one", "wilson"]
