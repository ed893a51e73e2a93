"""The shipped scenario library as a whole (the rule scenarios also run one by one through the plugin)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from arena.cli import main
from arena.scenarios import load, load_all, run_one
from arena.scenarios.library import BEHAVIOUR, LIBRARY, RULES

RULE_ROWS = 25  # docs/rules.md; row 20 has no scenario (docs/scenarios.md, "The library")


def test_one_rule_scenario_per_row_and_behaviour_rates_are_measured():
    rows = sorted(int(p.name[:2]) for p in RULES.glob("*.scenario.toml"))
    assert rows == [n for n in range(1, RULE_ROWS + 1) if n != 20]
    rules_text = (Path(__file__).resolve().parents[2] / "docs" / "rules.md").read_text()
    assert f"| {RULE_ROWS} |" in rules_text and f"| {RULE_ROWS + 1} |" not in rules_text, (
        "a new rule row: add its scenario"
    )
    for path in BEHAVIOUR.glob("*.scenario.toml"):
        for sc in load_all(path):
            assert 0 < sc.spec.min_pass <= 1 and "seeds" in sc.spec.measured, sc.name


@pytest.mark.slow
def test_the_library_at_three_seeds_passes_with_one_junit_case_per_scenario(tmp_path):
    junit = tmp_path / "report.xml"
    assert main(["scenario", "run", str(LIBRARY), "--seeds", "3", "--jobs", "2", "--junit", str(junit)]) == 0
    cases = ET.parse(junit).getroot().findall("testcase")
    names = [sc.name for p in sorted(LIBRARY.rglob("*.scenario.toml")) for sc in load_all(p)]
    assert sorted(c.get("name") for c in cases) == sorted(names)


@pytest.mark.slow
def test_a_thousand_reruns_give_one_verdict_and_one_digest():
    sc = load(RULES / "09-goal.scenario.toml")
    first = run_one(sc, 7)
    for i in range(999):
        again = run_one(sc, 7)
        assert again == first, f"rerun {i + 1} differs: {again} != {first}"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["03-positioning-over", "13-corner", "19-dead-robot", "21-penalty"])
def test_both_engines_give_the_same_verdicts_and_digests(name):
    sc = load(RULES / f"{name}.scenario.toml")
    for seed in (0, 1):
        a, b = run_one(sc, seed, "inprocess"), run_one(sc, seed, "processes")
        assert (a.passed, a.failures, a.digest, a.score) == (b.passed, b.failures, b.digest, b.score), (seed, a, b)


@pytest.mark.slow
def test_bench_scenario_reports_runs_per_minute_and_the_ratio(capsys):
    import json

    assert main(["bench", "scenario", "--runs", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["simulated_s_per_run"] == 10.0 and out["runs_per_minute_one_core"] > 0
    assert out["ratio_to_plain_match"] == pytest.approx(
        out["run_wall_s_median"] / out["plain_match_wall_s_median"], rel=0.01
    )
