"""A scenario file as an experiment's base (docs/experiments.md, "A scenario as the base").

experiments/ (below this room) reads the experiment file and plays its runs; it knows a
scenario base only through what `base(path, name)` returns here, which the command line hands to
`design.load`. Each run is `run_one` of the scenario with the cell's values set over its match
configuration (`Scenario.settings`), so a row's verdict and digest are those of
`arena scenario run --seed S` of a scenario file that says the same settings.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from arena.config import ConfigError, MatchConfig
from arena.scenarios.model import Scenario, ScenarioError, load
from arena.scenarios.runner import run_one

# What a scenario's file fixes beyond its match configuration; the rest of a configuration may vary.
NOT_SCENARIO_FACTORS = {
    "timing.dt": "its steps and expectations are timed at the default tick",
    "robots": "its start and steps name its robots (play.robots in the file)",
}


@dataclass(frozen=True)
class ScenarioRun:
    """One cell's run at a seed, a worker's task (picklable): the verdict as an experiment's result."""

    scenario: Scenario

    def __call__(self, cfg: MatchConfig, engine: str) -> dict:
        v = run_one(self.scenario, cfg.seed, engine)
        failures = "; ".join(f"{f.name} at tick {f.tick}" for f in v.failures)
        return {
            "score": list(v.score),
            "robots": 0,  # no metres per robot: a scenario's responses are its pass and its score
            "distance_m": {},
            "digest": v.digest,
            "extra": {"pass": int(v.passed), **v.drawn, "failures": failures},
        }


@dataclass(frozen=True)
class ScenarioBase:
    """What experiments/design.py asks of a scenario base."""

    scenario: Scenario

    @property
    def name(self) -> str:
        return self.scenario.name

    @property
    def path(self) -> str:
        return self.scenario.path

    def at(self, cell: dict[str, Any]) -> Scenario:
        return dataclasses.replace(self.scenario, settings=tuple(cell.items()))

    def match(self, cell: dict[str, Any], seed: int) -> MatchConfig:
        """The match the cell plays at `seed` (the scenario's draws are the seed's)."""
        return self.at(cell).config(seed)

    def task(self, cell: dict[str, Any]) -> ScenarioRun:
        return ScenarioRun(self.at(cell))

    def check_factor(self, path: str) -> str:
        """Why `path` cannot vary over this scenario, or ''."""
        return NOT_SCENARIO_FACTORS.get(path, "")


def base(path: str, name: str) -> ScenarioBase:
    """The scenario `name` of the file (or its only one) as a base; ConfigError (one line) if bad."""
    try:
        sc = load(path, name)
    except (ScenarioError, OSError) as exc:
        raise ConfigError(f"base: {exc}") from None
    if sc.spec.play.external:
        raise ConfigError(f"base: {path}: scenario {sc.name!r} has external processes; an experiment plays none")
    return ScenarioBase(sc)
