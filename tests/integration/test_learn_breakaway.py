"""examples/learn_breakaway/cem.py runs end to end on a tiny budget, writes its files, and the policy
file it writes plays `arena match` (docs/learning.md, "An example against a defender")."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).parents[2] / "examples" / "learn_breakaway" / "cem.py"


def test_the_breakaway_example_trains_evaluates_and_writes_a_policy_that_plays_a_match(tmp_path):
    pytest.importorskip("onnxruntime", reason="pip install 'soccer-arena[learn]'")
    pytest.importorskip("matplotlib")
    out = tmp_path / "run"
    tiny = ["--iterations", "2", "--population", "3", "--seeds-per-candidate", "1", "--eval-seeds", "2"]
    r = subprocess.run(
        [sys.executable, str(EXAMPLE), "--out", str(out), *tiny, "--workers", "2"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    assert {p.name for p in out.iterdir()} == {
        "learning-curve.png",
        "policy.onnx",
        "results.json",
        "breakaway.scenario.toml",
    }
    result = json.loads((out / "results.json").read_text())
    assert [c["iteration"] for c in result["curve"]] == [1, 2]
    assert result["curve"][0]["stage"] == "breakaway from the penalty area"  # the curriculum's easiest start
    assert result["task"] == "breakaway from midfield" and result["eval_seeds"] == 2
    for name in ("trained", "untrained", "random_initial"):
        assert 0 <= result[name]["goals"] <= 2
    assert result["untrained"] == {"mean_return": 0.0, "goals": 0}  # all weights zero: it stands still
    assert result["training_cpu_seconds"] > 0

    m = subprocess.run(
        [sys.executable, "-m", "arena", "match", "--home", f"policy:{out / 'policy.onnx'}", "--away", "BS"]
        + ["--half-time", "1", "--engine", "inprocess", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert m.returncode == 0, m.stderr[-3000:]
    played = json.loads(m.stdout)
    assert played["outcome"] == "completed" and played["home"] == f"policy:{out / 'policy.onnx'}"

    s = subprocess.run(
        [sys.executable, "-m", "arena", "scenario", "run", str(out / "breakaway.scenario.toml"), "--seed", "0"]
        + ["--json", "--records", str(tmp_path / "records")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert s.returncode in (0, 1), s.stderr[-3000:]  # 1: judged, and team a did not score
    (judged,) = json.loads(s.stdout)["scenarios"]
    assert judged["scenario"] == "breakaway from midfield" and len(judged["runs"]) == 1
