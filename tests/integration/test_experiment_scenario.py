"""A scenario file as an experiment's base, end to end: each cell and seed is the scenario's run with
the cell's settings, its `pass` and digest those of `arena scenario run --seed S` of a scenario
file that says the same settings; a bad scenario base is one line, exit 2."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from tests.integration.helpers import ARENA

LIBRARY = Path(__file__).resolve().parents[2] / "scenarios" / "library"
CORNER = LIBRARY / "behaviour" / "corner-routine.scenario.toml"  # randomised starts; ~10 % pass
LEVELS = (0, 6)  # perception latency [ticks]: at seed 2 the routine scores at 0, not at 6


def arena(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*ARENA, *args], capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("scen")
    f = tmp / "corner.toml"
    f.write_text(
        f'base = "{CORNER}"\nseeds = 3\nresponses = ["pass", "goals_for"]\n'
        f'[factors]\n"timing.perception_latency" = {list(LEVELS)}\n'
    )
    out = tmp / "out"
    r = arena("experiment", "run", str(f), "--out", str(out), "--jobs", "1", "--json")
    assert r.returncode == 0, r.stderr[-3000:]
    return tmp, json.loads(r.stdout), json.loads((out / "rows.json").read_text())


def test_each_run_is_arena_scenario_run_of_that_cell(played):
    tmp, _, rows = played
    assert len(rows) == len(LEVELS) * 3 and {r["team"] for r in rows} == {"a"}  # no swapped ends
    for level in LEVELS:  # the same scenario, the factor's value written into the file
        variant = tmp / f"corner-l{level}.scenario.toml"
        text = CORNER.read_text().replace("[scenario.play]\n", f"[scenario.play]\nperception_latency = {level}\n")
        variant.write_text(text)
        for seed in range(3):
            r = arena("scenario", "run", str(variant), "--seed", str(seed), "--records", str(tmp / "runs"), "--json")
            assert r.returncode in (0, 1), r.stderr[-3000:]  # 1: the scenario failed at this seed
            got = json.loads(r.stdout)["scenarios"][0]["runs"][0]
            row = next(r for r in rows if r["timing.perception_latency"] == level and r["seed"] == seed)
            assert (row["pass"], row["digest"]) == (int(got["passed"]), got["digest"]), (level, seed)
            for key, value in got["drawn"].items():  # the run's drawn start is in its row
                assert row[key] == value
    passes = {(r["timing.perception_latency"], r["seed"]): r["pass"] for r in rows}
    assert passes[(0, 2)] == 1 and passes[(6, 2)] == 0  # the factor decides this run: the test can fail


def test_the_pass_rate_has_the_wilson_interval(played):
    from arena.scenarios import wilson

    _, summary, rows = played
    assert summary["responses"] == ["pass", "goals_for"]
    for cell in summary["cells"]:
        runs = [r["pass"] for r in rows if r["cell"] == cell["cell"]]
        lo, hi = wilson(sum(runs), len(runs))
        assert cell["pass"]["mean"] == round(sum(runs) / 3, 4)
        assert (cell["pass"]["low"], cell["pass"]["high"]) == (round(lo, 4), round(hi, 4))


@pytest.mark.parametrize(
    "text, error",
    [
        (f'base = "{CORNER}"\nopponents = ["AD"]\n', "opponents: a scenario fixes its sides"),
        (f'base = "{CORNER}"\nresponses = ["shots"]\n', "unknown response 'shots' over a scenario base"),
        (f'base = "{CORNER}"\nscenario = "nope"\n', "no scenario named 'nope'"),
        (f'base = "{CORNER}"\n[factors]\n"timing.dt" = [0.01]\n', "factors.timing.dt: not over a scenario"),
        (f'base = "{CORNER}"\n[factors]\nrobots = [1]\n', "factors.robots: not over a scenario"),
        ('base = "missing.scenario.toml"\n', "missing.scenario.toml"),
        ('scenario = "x"\n[base]\nhalf_time = 5.0\n', "scenario: names a scenario of a base scenario file"),
        ('responses = ["pass"]\n', "pass is a scenario base's"),
    ],
)
def test_a_bad_scenario_base_is_one_line_exit_2(tmp_path, text, error):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    r = arena("experiment", "run", str(f), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and error in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
