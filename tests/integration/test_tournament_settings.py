"""Issue 19: a tournament records what it was played with, and --resume refuses to mix settings."""

from __future__ import annotations

import json
import subprocess

from arena.tools.tournament import Result, report
from tests.integration.helpers import ARENA

ARGS = ("tournament", "--strategies", "BS,AD", "--legs", "1", "--half-time", "2", "--seed", "5", "--jobs", "1")


def test_settings_are_recorded_and_resume_refuses_a_different_half_time(tmp_path):
    out = tmp_path / "t"
    r = subprocess.run([*ARENA, *ARGS, "--out", str(out), "--json"], capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stderr
    saved = json.loads((out / "tournament.json").read_text())["settings"]
    assert saved["strategies"] == ["basic-static", "advance-dynamic"]
    assert (saved["legs"], saved["half_time"], saved["robots"], saved["seed"]) == (1, 2.0, 3, 5)
    assert (saved["link"], saved["link_overrides"], saved["engine"]) == ("ideal", {}, "processes")
    assert saved["version"][0].isdigit()
    md = (out / "report.md").read_text()
    assert "1 leg, seed 5" in md and "1 of 1 match played" in md and "half time 2" in md

    again = [*ARENA, *ARGS[:-4], "--seed", "5", "--jobs", "1", "--out", str(out), "--resume"]
    assert again[again.index("--half-time") + 1] == "2"
    again[again.index("--half-time") + 1] = "3"
    r = subprocess.run(again, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "--half-time 2 there, 3 now" in r.stderr
    assert json.loads((out / "tournament.json").read_text())["settings"]["half_time"] == 2.0, "nothing was mixed in"


def test_a_partial_report_counts_the_whole_schedule(tmp_path):
    one = Result(
        id="x",
        first="advance-dynamic",
        second="basic-static",
        leg=1,
        home="basic-static",
        away="advance-dynamic",
        seed=1,
        status="ok",
        score=[1, 0],
        distance_m={},
    )
    summary = report([one], ["advance-dynamic", "basic-static"], 3, tmp_path, 1.0, 0, total=6)
    assert (summary["played"], summary["scheduled"]) == (1, 6)
    assert "1 of 6 matches played" in (tmp_path / "report.md").read_text()
    assert "3 legs" in (tmp_path / "report.md").read_text()
