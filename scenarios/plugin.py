"""The pytest plugin (entry point `pytest11`): `*.scenario.toml` files collect as tests.

One test item per scenario: it runs at seeds 0..N-1 (`--scenario-seeds N`,
default 1) on `--scenario-engine` (inprocess) and passes when the pass rate
reaches the scenario's `min_pass`; a failure prints every failed expectation
with its tick, seed and replay command. A file that cannot be read fails its
collection with the one-line reason. The `arena_scenario` fixture runs a
scenario from Python and returns its `Outcome`.
"""

from __future__ import annotations

import argparse

import pytest

from arena.scenarios.model import SUFFIX, ScenarioError, load, load_all


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("arena scenarios")
    group.addoption("--scenario-seeds", type=_seeds, default=1, metavar="N", help="seeds 0..N-1 per scenario (1)")
    group.addoption("--scenario-engine", default="inprocess", choices=("inprocess", "processes"), help="(inprocess)")


def _seeds(text: str) -> int:
    """--scenario-seeds: a whole number >= 1 (0 was quietly taken as 1)."""
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return n


def pytest_collect_file(file_path, parent):
    if file_path.name.endswith(SUFFIX):
        return ScenarioFile.from_parent(parent, path=file_path)
    return None


def play(scenario, seeds: int, engine: str):
    from arena.scenarios.runner import Outcome, run_one

    return Outcome(scenario, [run_one(scenario, s, engine) for s in range(seeds)])


class ScenarioFailed(Exception):
    def __init__(self, outcome):
        super().__init__(outcome.describe())
        self.outcome = outcome


class ScenarioFile(pytest.File):
    def collect(self):
        try:
            scenarios = load_all(self.path)
        except ScenarioError as exc:
            raise self.CollectError(str(exc)) from None
        for sc in scenarios:
            yield ScenarioItem.from_parent(self, name=sc.name, scenario=sc)


class ScenarioItem(pytest.Item):
    def __init__(self, *, scenario, **kwargs):
        super().__init__(**kwargs)
        self.scenario = scenario

    def runtest(self) -> None:
        opt = self.config.getoption
        outcome = play(self.scenario, opt("scenario_seeds"), opt("scenario_engine"))
        if not outcome.passed:
            raise ScenarioFailed(outcome)

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, ScenarioFailed):
            return str(excinfo.value)
        return super().repr_failure(excinfo, style=style)

    def reportinfo(self):
        return self.path, None, f"scenario {self.name}"


@pytest.fixture
def arena_scenario():
    """Run a scenario file from Python: `arena_scenario(path, name="", seeds=1, engine="inprocess") -> Outcome`."""

    def run(path, name: str = "", seeds: int = 1, engine: str = "inprocess"):
        return play(load(path, name), seeds, engine)

    return run
