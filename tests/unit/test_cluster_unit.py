"""experiments/cluster.py without Ray: address and runtime_env parsing, the version fingerprint, one attempt's result.

The real cluster is exercised in tests/integration/test_cluster.py.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from types import SimpleNamespace

import pytest

from arena.config import ConfigError
from arena.experiments import cluster
from arena.experiments.fixtures import Fixture

ROOT = Path(__file__).resolve().parents[2]


def test_fingerprint_covers_every_installed_package():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    top = {p.split(".")[1] for p in declared if p.count(".") >= 1}
    assert top == set(cluster.PACKAGES), "add the new package to cluster.PACKAGES so the version check sees it"
    fp = cluster.fingerprint()
    assert set(fp) == {"version", "git", "source"} and len(fp["source"]) == 16
    assert cluster.source_hash() == fp["source"]


@pytest.mark.parametrize(
    ("text", "want"),
    [(None, None), ("", None), ("auto", "auto"), ("10.0.0.5:6379", "10.0.0.5:6379"), ("[::1]:6379", "[::1]:6379")],
)
def test_addresses(text, want):
    assert cluster.parse_address(text) == want


@pytest.mark.parametrize("text", ["nowhere", "host:", ":6379", "host:0", "host:70000", "host:port"])
def test_bad_addresses(text):
    with pytest.raises(ConfigError, match="HOST:PORT"):
        cluster.parse_address(text)


def test_runtime_env():
    assert cluster.parse_runtime_env(None) is None
    assert cluster.parse_runtime_env('{"pip": ["x"]}') == {"pip": ["x"]}
    for bad in ("{pip", "[1]", "3"):
        with pytest.raises(ConfigError, match="--ray-runtime-env"):
            cluster.parse_runtime_env(bad)


def test_task_cpus_by_engine():
    assert cluster.task_cpus("processes") == 2.0
    assert cluster.task_cpus("inprocess") == 1.0


@pytest.fixture
def runner(tmp_path):
    (tmp_path / "matches").mkdir()
    (tmp_path / "logs").mkdir()
    return SimpleNamespace(matches_dir=tmp_path / "matches", logs_dir=tmp_path / "logs", engine="processes")


FX = Fixture(0, "basic-static", "advance-dynamic", 1, "basic-static", "advance-dynamic", 42)


@pytest.fixture(scope="module")
def match():
    """A match's result as a task returns it (what it played is the driver's to read, not ours here)."""
    from msgspec.structs import replace

    from arena.config import MatchConfig
    from arena.match import play

    played = play(MatchConfig(half_time=0.2))
    return replace(played, score=[1, 2], distance_m={"a/1": 3.0}, rtf=20.0, digest="d" * 32, engine="processes")


def test_an_ok_attempt_is_written_once(runner, match):
    r = cluster.finish(runner, FX, 1, {"rc": 0, "match": match, "err": "", "wall": 1.5, "node": "n1"})
    assert r.status == "ok" and r.score == [1, 2] and r.attempts == 1 and r.engine == "processes"
    saved = json.loads((runner.matches_dir / f"{FX.id}.json").read_text())
    assert saved["digest"] == match.digest
    assert "played on node n1" in (runner.logs_dir / f"{FX.id}.log").read_text()


def test_a_failed_attempt_is_played_again_then_recorded(runner):
    mismatch = {"rc": -1, "reason": "version mismatch on node n2: ...", "node": "n2"}
    assert cluster.finish(runner, FX, 1, mismatch) is None
    assert not (runner.matches_dir / f"{FX.id}.json").exists()
    r = cluster.finish(runner, FX, 2, mismatch)
    assert r.status == "failed" and r.attempts == 2 and r.reason.startswith("version mismatch")
    no_result = {"rc": 0, "reason": "the match printed no result (JSON is malformed)", "err": "", "wall": 1.0}
    printed = cluster.finish(runner, FX, 2, no_result)
    assert printed.status == "failed" and printed.reason.startswith("the match printed no result")
    crashed = cluster.finish(runner, FX, 2, {"rc": 1, "out": "", "err": "boom\nlast line\n", "wall": 1.0})
    assert crashed.reason == "last line"


def test_ray_missing_is_refused_before_anything_is_written(tmp_path, monkeypatch):
    """`--ray` without Ray failed, but only after logs/, matches/ and settings.json were made."""
    import sys

    from arena.config import ConfigError
    from arena.experiments import tournament

    monkeypatch.setitem(sys.modules, "ray", None)  # as if not installed
    out = tmp_path / "t"
    opts = tournament.TournamentOptions(strategies=("advance-dynamic", "basic-static"), out=out, ray="")
    with pytest.raises(ConfigError, match=r"--ray needs Ray: pip install"):
        tournament.run(opts)
    assert not out.exists()
