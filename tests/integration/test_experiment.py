"""`arena experiment run` and `compare` end to end, as real `arena` processes: an experiment
file written from docs/experiments.md (two factors, three levels, four seeds), its rows and
digests against `arena match --config`, --resume, and the SPRT's verdicts."""

from __future__ import annotations

import csv
import json
import subprocess

import pytest

from tests.integration.helpers import ARENA, arena_json

# As docs/experiments.md's first example: two factors, three levels each, four seeds.
TWO_FACTORS = """
name = "two-factors"
seeds = 4

[base]
home = "AD"
away = "BS"
half_time = 6.0

[factors]
"links.wifi.latency_ms" = [0.0, 40.0, 120.0]
"rules.kickoff_time" = [1.0, 1.5, 2.0]
"""


def arena(*args: str, timeout: float = 600.0) -> subprocess.CompletedProcess:
    return subprocess.run([*ARENA, *args], capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("exp")
    f = tmp / "two.toml"
    f.write_text(TWO_FACTORS)
    out = tmp / "out"
    r = arena("experiment", "run", str(f), "--out", str(out), "--jobs", "2", "--json")
    assert r.returncode == 0, r.stderr[-3000:]
    return f, out, json.loads(r.stdout)


def test_one_row_per_match_and_a_summary(played):
    f, out, summary = played
    with open(out / "rows.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 9 * 4 * 2 == summary["matches"] and summary["failed"] == 0
    assert rows == [{k: str(v) for k, v in r.items()} for r in json.loads((out / "rows.json").read_text())]
    assert {r["team"] for r in rows} == {"a", "b"} and {r["seed"] for r in rows} == {"0", "1", "2", "3"}
    assert len({r["digest"] for r in rows}) == len(rows)  # every match its own
    for r in rows:
        assert int(r["points"]) == {"1": 3, "0": 0}.get(r["win"], 1) if r["draw"] == "0" else int(r["points"]) == 1
        assert int(r["goal_diff"]) == int(r["goals_for"]) - int(r["goals_against"])
    cell = summary["cells"][4]
    assert cell["links.wifi.latency_ms"] == 40.0 and cell["rules.kickoff_time"] == 1.5
    assert cell["points"]["low"] <= cell["points"]["mean"] <= cell["points"]["high"]
    assert "diff" in cell["points"] and "diff" not in summary["cells"][0]["points"]
    assert sorted(p.name for p in (out / "plots").iterdir()) == sorted(f"{r}.png" for r in summary["responses"])
    report = (out / "report.md").read_text()
    assert "| c008 | 120 | 2 | AD | 8 |" in report and "![points](plots/points.png)" in report


def test_a_rules_value_reaches_every_match(played):
    _, out, _ = played
    rows = json.loads((out / "rows.json").read_text())
    by = {(r["links.wifi.latency_ms"], r["rules.kickoff_time"], r["seed"], r["team"]): r["digest"] for r in rows}
    for lat in (0.0, 40.0, 120.0):
        for seed in range(4):
            assert len({by[(lat, k, seed, t)] for k in (1.0, 1.5, 2.0) for t in "ab"}) == 6


@pytest.mark.parametrize("match_id", ["c004-BS-s2-b", "c008-BS-s1-a"])
def test_digest_equals_arena_match_of_that_cell_and_seed(played, match_id):
    _, out, _ = played
    row = json.loads((out / "matches" / f"{match_id}.json").read_text())
    m = arena_json(
        "match", "--config", str(out / row["config"]), "--seed", str(row["seed"]),
        "--home", row["team_a"], "--away", row["team_b"], "--engine", "inprocess",
    )  # fmt: skip
    assert m["digest"] == row["digest"]


def test_resume_plays_only_what_is_missing(played, tmp_path):
    f, out, _ = played
    import shutil

    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    gone = sorted((copy / "matches").iterdir())[:3]
    for p in gone:
        p.unlink()
    again = arena("experiment", "run", str(f), "--out", str(copy), "--jobs", "1")
    assert again.returncode == 2 and "--resume" in again.stderr  # never over an old run by accident
    r = arena("experiment", "run", str(f), "--out", str(copy), "--jobs", "1", "--resume", "--json")
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stderr.count("] c0") == 3  # three matches played, one progress line each

    def rows(d):  # the CPU time of a match replayed differs; what it played does not
        return [{k: v for k, v in r.items() if k != "cpu_s"} for r in json.loads((d / "rows.json").read_text())]

    assert rows(copy) == rows(out)


def test_facts_responses(tmp_path):
    f = tmp_path / "facts.toml"
    f.write_text(
        'seeds = 1\nresponses = ["points", "shots", "saves", "coverage_r1"]\n'
        '[base]\nhome = "AD"\naway = "BS"\nhalf_time = 10.0\n'
    )
    r = arena("experiment", "run", str(f), "--out", str(tmp_path / "o"), "--jobs", "1", "--json")
    assert r.returncode == 0, r.stderr[-2000:]
    rows = json.loads((tmp_path / "o" / "rows.json").read_text())
    assert len(rows) == 2 and all(isinstance(row["shots"], int) and row["coverage_r1"] > 0 for row in rows)


@pytest.mark.parametrize(
    "text, error",
    [("bogus = 1\n", "unknown key 'bogus'"), ('[factors]\n"rules.nope" = [1]\n', "no such configuration field")],
)
def test_bad_file_is_one_line_exit_2(tmp_path, text, error):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    r = arena("experiment", "run", str(f), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and error in r.stderr and len(r.stderr.strip().splitlines()) == 1


def compare(*args: str) -> tuple[int, dict]:
    r = arena("experiment", "compare", *args, "--json", timeout=1800)
    assert r.returncode in (0, 1, 3), r.stderr[-2000:]
    out = json.loads(r.stdout)
    assert out["exit"] == r.returncode
    return r.returncode, out


@pytest.mark.slow
def test_ad_is_accepted_better_than_bs_within_a_few_dozen_pairs():
    """2 x 30 s halves; bounds [0, 50] normalised Elo (fishtest's default [0, 2] is for changes of
    a few Elo over tens of thousands of games; docs/experiments.md)."""
    code, out = compare("--candidate", "AD", "--baseline", "BS", "--half-time", "30", "--elo1", "50",
                        "--max-pairs", "60", "--jobs", "2")  # fmt: skip
    assert code == 0 and out["state"] == "accepted" and out["pairs"] <= 48, out["line"]


@pytest.mark.slow
@pytest.mark.parametrize("opponents", ["", "AS,BD"])
def test_a_strategy_against_itself_is_never_accepted_better(opponents):
    args = ["--candidate", "BS", "--baseline", "BS", "--half-time", "10", "--elo1", "50", "--max-pairs", "20"]
    if opponents:  # the baseline under another name: the same matches, every game drawn
        args = ["--candidate", "BS", "--baseline", "basic-static", "--opponents", opponents, *args[4:]]
        r = arena("experiment", "compare", *args)
        assert r.returncode == 2 and "name two" in r.stderr
        return
    code, out = compare(*args, "--jobs", "2", "--first-seed", "100")
    assert code != 0 and out["state"] != "accepted", out["line"]
    assert out["penta"] == [0, 0, 20, 0, 0]  # both ends are the very same match: every pair is drawn
