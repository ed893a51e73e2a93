"""A scenario file as an experiment's base, as loaded: one run per cell and seed, the cell's settings
over the scenario's match configuration, and the loader the command line hands in."""

from __future__ import annotations

from pathlib import Path

import pytest

from arena.config import ConfigError
from arena.experiments import design
from arena.scenarios import load
from arena.scenarios.experiment import base as scenario_base

CORNER = Path(__file__).resolve().parents[2] / "scenarios" / "library" / "behaviour" / "corner-routine.scenario.toml"


def _file(tmp_path, text: str) -> str:
    path = tmp_path / "e.toml"
    path.write_text(f'base = "{CORNER}"\nseeds = 2\n{text}')
    return str(path)


def test_one_run_per_cell_and_seed_with_the_cell_settings_over_the_scenario(tmp_path):
    exp = design.load(_file(tmp_path, '[factors]\n"timing.perception_latency" = [0, 6]\n"rules.kickoff_time" = [2.0]\n'),
                      scenarios=scenario_base)  # fmt: skip
    assert exp.responses == ["pass"] and [m["id"] for m in exp.matches()] == [
        "c000-s0",
        "c000-s1",
        "c001-s0",
        "c001-s1",
    ]
    sc = load(CORNER)
    for m in exp.matches():
        cfg, own = exp.match_config(m), sc.config(m["seed"])
        assert cfg.timing.perception_latency == exp.cells[m["cell"]]["timing.perception_latency"]
        assert cfg.rules.kickoff_time == 2.0 and cfg.seed == m["seed"]
        assert cfg.scenario == own.scenario and (cfg.home, cfg.away) == (own.home, own.away)  # the seed's draws
    assert exp.match_config(exp.matches()[0]).scenario != exp.match_config(exp.matches()[1]).scenario


def test_settings_equal_to_the_scenario_own_change_nothing():
    import dataclasses

    sc = load(CORNER)
    same = dataclasses.replace(sc, settings=(("timing.perception_latency", sc.spec.play.perception_latency),))
    assert same.config(4) == sc.config(4)


def test_without_the_loader_a_scenario_base_is_refused(tmp_path):
    with pytest.raises(ConfigError, match="a scenario file is a base for arena experiment run"):
        design.load(_file(tmp_path, ""))
