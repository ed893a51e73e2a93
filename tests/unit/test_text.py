"""Issue 19 part 6: units that rich does not swallow, `arena --version`, `arena strategies`."""

from __future__ import annotations

import functools
import json
import subprocess
import sys

from msgspec.structs import replace
from rich.console import Console

from arena.config import MatchConfig
from arena.match import MatchResult, play
from arena.match.result import LinkStats
from arena.review import report
from tests.integration.helpers import arena_in_process


def arena(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arena", *args], capture_output=True, text=True, timeout=120)


@functools.cache
def played() -> MatchResult:
    return play(MatchConfig(half_time=0.2))


def match_result() -> MatchResult:
    """A match's result with the values `report.print_match` is checked on."""
    return replace(
        played(),
        home="basic-static",
        away="chase",
        score=[1, 0],
        seed=7,
        link="wifi",
        links={"wifi": LinkStats(sent=10, dropped=1, drop_rate=0.1, delay_ms_mean=3.0, delay_ms_p95=5.0)},
        distance_m={"a/1": 12.5},
        events={},
    )


def test_units_in_table_headers_survive_rich():
    console = Console(record=True, width=120)
    report.print_match(match_result(), console)
    text = console.export_text()
    assert "robot [m]" in text and "┃  [m] ┃" in text, text  # the title and the unit column
    assert "delay mean [ms]" in text and "dropped [%]" in text


def test_a_recorder_that_failed_is_reported_not_a_crash():
    console = Console(record=True, width=200)
    why = "the recorder failed: exited with code 2"
    report.print_match(
        replace(match_result(), recording={"path": "/x/m.mcap", "complete": False, "error": why}), console
    )
    assert f"not recorded: {why} (/x/m.mcap)" in console.export_text()


def test_a_refbox_that_never_answered_is_said():
    console = Console(record=True, width=200)
    follow = {"endpoint": "10.0.0.9:28097", "connected": False, "applied": 0, "ignored": {}, "errors": 0}
    report.print_match(replace(match_result(), refbox_follow=follow), console)
    assert "refbox-follow 10.0.0.9:28097: never connected; 0 commands applied" in console.export_text()


def test_version_matches_the_package():
    from importlib.metadata import version

    r = arena("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"arena {version('soccer-arena')}"


def test_strategies_lists_name_alias_source_and_conformance(capfd, tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))  # the suite's verdicts are kept there
    r = arena_in_process(["strategies", "chase", "BS", "--json"], capfd)
    assert r.returncode == 0, r.stderr
    rows = {row["name"]: row for row in json.loads(r.stdout)["strategies"]}
    assert set(rows) == {"chase", "basic-static"}
    assert rows["basic-static"]["aliases"] == ["BS"]
    assert rows["basic-static"]["source"] == "built-in arena.strategies.iris"
    assert rows["chase"]["conformance"] == "passes"
    listed = json.loads(arena_in_process(["strategies", "--no-check", "--json"], capfd).stdout)["strategies"]
    assert {"basic-static", "basic-dynamic", "advance-static", "advance-dynamic", "chase"} <= {
        x["name"] for x in listed
    }
    assert all(x["conformance"] == "not checked" for x in listed)
