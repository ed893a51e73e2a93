"""`arena facts --json`: one JSON object on stdout, its totals those of its matches, and every
key it prints explained in docs/strategies.md ("`arena facts --json`")."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

DOC = (Path(__file__).parents[2] / "docs" / "strategies.md").read_text().split("### `arena facts --json`", 1)[1]
DOC = DOC.split("\n## ", 1)[0]


def facts_json(*args: str) -> dict:
    run = subprocess.run(
        [sys.executable, "-m", "arena", "facts", *args, "--json"], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)  # nothing else on stdout


def undocumented(keys) -> list[str]:
    return [k for k in keys if f"`{k}`" not in DOC]


def test_seeds_as_json_add_up_and_are_documented():
    out = facts_json("--seeds", "2", "--first-seed", "3", "--home", "AD", "--away", "BS", "--half-time", "4")
    assert [m["seed"] for m in out["matches"]] == [3, 4]
    assert out["perception_latency"] == 3
    ad = out["strategies"]["advance-dynamic"]  # named in full, as by arena match and tournament.json
    assert ad["sides"] == 2
    assert ad["GF"] == sum(m["teams"][0]["goals"] for m in out["matches"])
    assert ad["GA"] == sum(m["teams"][1]["goals"] for m in out["matches"])
    assert ad["robot1_m"] == sum(m["teams"][0]["distance_m"][1] for m in out["matches"])
    assert ad["W"] + ad["D"] + ad["L"] == 2
    match, team = out["matches"][0], out["matches"][0]["teams"][0]
    assert undocumented([*out, *match, *team, *ad]) == []


def test_a_strategy_is_one_strategy_by_any_of_its_names():
    out = facts_json("--seeds", "1", "--home", "AD", "--away", "advance-dynamic", "--half-time", "1")
    assert list(out["strategies"]) == ["advance-dynamic"] and out["strategies"]["advance-dynamic"]["sides"] == 2


def test_round_robin_as_json_has_the_table():
    out = facts_json("--round-robin", "AD,BS", "--legs", "2", "--half-time", "2", "--perception-latency", "0")
    assert out["perception_latency"] == 0
    names = {"advance-dynamic", "basic-static"}
    assert {row["team"] for row in out["standings"]} == names == set(out["coverage"]) == set(out["strategies"])
    assert sum(row["W"] + row["D"] + row["L"] for row in out["standings"]) == 4
    assert undocumented([*out, *out["standings"][0], *out["coverage"]["basic-static"]]) == []


def test_the_printed_lines_say_what_their_two_numbers_are():
    """`by-fence stuck 1.1/0.0 robot-s` was printed with nothing saying which team each number is."""
    run = subprocess.run(
        [sys.executable, "-m", "arena", "facts", "--seeds", "1", "--home", "AD", "--away", "BS", "--half-time", "1"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    first = next(i for i, s in enumerate(lines) if s.startswith("seed "))
    explained = "\n".join(lines[:first])
    assert "x/y = team a (home) / team b (away)" in explained
    for word in ("outside", "stall", "stuck", "by-fence stuck", "corner", "pushing", "contact", "overlap", "saves"):
        assert word in lines[first] + lines[first + 1] and word in explained, word


def test_the_summary_header_has_a_legend_for_its_terse_columns():
    """`conceded-stuck` and `robot1/robot2` were printed without saying what they count."""
    run = subprocess.run(
        [sys.executable, "-m", "arena", "facts", "--seeds", "1", "--home", "AD", "--away", "BS", "--half-time", "2"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("strategy  sides"))
    legend = lines[header + 1]
    assert "conceded-stuck: goals it conceded while one of them was stuck" in legend, legend
    assert "robot1/robot2: metres run by outfield robot 1 over robot 2" in legend, legend
