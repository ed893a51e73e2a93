"""Issue 19: a tournament records what it was played with, and --resume refuses to mix settings."""

from __future__ import annotations

import dataclasses
import json
import subprocess

import pytest

from arena.config import ConfigError
from arena.experiments.fixtures import Result
from arena.experiments.tournament import TournamentOptions, check_resume, settings
from arena.experiments.tournament_report import report
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
    assert saved["perception_latency"] == 3, "the default model"
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


def test_resume_refuses_another_perception_latency_and_an_old_directory_counts_as_0(tmp_path):
    opts = TournamentOptions(strategies=("basic-static", "advance-dynamic"))
    now = settings(opts)
    (tmp_path / "settings.json").write_text(json.dumps(now))
    check_resume(tmp_path, now)
    base = opts.base.replace(timing=dataclasses.replace(opts.base.timing, perception_latency=0))
    with pytest.raises(ConfigError, match="--perception-latency 3 there, 0 now"):
        check_resume(tmp_path, settings(dataclasses.replace(opts, base=base)))
    # A directory written before the setting was recorded was played with L = 0, the default then.
    (tmp_path / "settings.json").write_text(json.dumps({k: v for k, v in now.items() if k != "perception_latency"}))
    check_resume(tmp_path, settings(dataclasses.replace(opts, base=base)))
    with pytest.raises(ConfigError, match="--perception-latency 0 there, 3 now"):
        check_resume(tmp_path, now)


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


def test_resume_refuses_another_rules_value_and_an_old_directory_counts_as_the_defaults(tmp_path):
    opts = TournamentOptions(strategies=("basic-static", "advance-dynamic"))
    now = settings(opts)
    assert now["config"] == {}
    (tmp_path / "settings.json").write_text(json.dumps({k: v for k, v in now.items() if k != "config"}))
    check_resume(tmp_path, now)
    base = opts.base.replace(rules=dataclasses.replace(opts.base.rules, kickoff_time=0.5))
    with pytest.raises(ConfigError, match="--config none there, rules.kickoff_time=0.5 now"):
        check_resume(tmp_path, settings(dataclasses.replace(opts, base=base)))
