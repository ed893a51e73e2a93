"""`arena tournament` end to end: Ctrl-C keeps finished matches, --resume completes the rest."""

from __future__ import annotations

import json
import os
import signal
import subprocess
from pathlib import Path

import pytest

from tests.integration.helpers import ARENA, arena_json, cmdline, descendants, spawn, wait_for

ARGS = ("tournament", "--strategies", "BS,AD", "--legs", "3", "--half-time", "2", "--seed", "5", "--jobs", "1")
# One process plays a match of 2 x 2 s in a blink; 2 x 20 s takes it about a second, so the
# signal sent once the first match is in lands in the second or third (the test polls every 50 ms).
INPROCESS = ("--engine", "inprocess", "--half-time", "20")


@pytest.mark.parametrize(
    ("sig", "engine"),
    [(signal.SIGINT, ()), (signal.SIGTERM, ()), (signal.SIGINT, INPROCESS)],
    ids=["ctrl-c", "sigterm", "ctrl-c-inprocess"],
)
def test_interrupt_then_resume(tmp_path, reap, sig, engine):
    out = tmp_path / "t"
    args = (*ARGS, *engine)
    proc = spawn(*args, "--out", str(out))
    reap.append(proc)
    matches = out / "matches"
    wait_for(lambda: matches.is_dir() and any(matches.glob("*.json")), 120, "the first finished match")
    kids = descendants(proc.pid)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    wait_for(
        lambda: not any(os.path.exists(f"/proc/{k}") and "arena" in cmdline(k) for k in kids),
        20,
        "the running match to be stopped with the tournament",
    )
    assert "--resume" in err and "Traceback" not in err
    kept = sorted(p.name for p in matches.glob("*.json"))
    assert 1 <= len(kept) < 3
    assert not list(matches.glob("*.tmp")), "results are written atomically"

    summary = arena_json(*args, "--out", str(out), "--resume")
    assert summary["skipped"] == len(kept)
    assert len(summary["matches"]) == 3 and summary["failed"] == []
    table = {row["team"]: row for row in summary["table"]}
    for row in table.values():
        assert row["W"] + row["D"] + row["L"] == 3
        assert row["P"] == 3 * row["W"] + row["D"]
    assert sum(r["GF"] for r in table.values()) == sum(r["GA"] for r in table.values())
    saved = json.loads((out / "tournament.json").read_text())
    assert saved["table"] == summary["table"]
    for name in (
        "report.md",
        "table1.csv",
        "table2.csv",
        "coverage.csv",
        "ratings.csv",
        "goal_difference.png",
        "coverage.png",
    ):
        assert (out / name).stat().st_size > 0, name


def test_resume_says_how_many_matches_it_kept(tmp_path):
    """A mistyped --out with --resume must not start again from nothing without a word."""
    args = ("tournament", "--strategies", "BS,AD", "--legs", "2", "--half-time", "1", "--jobs", "1", *INPROCESS[:2])
    out = str(tmp_path / "nothing-here-yet")
    typo = subprocess.run(
        [*ARENA, *args, "--out", out, "--resume", "--json"], capture_output=True, text=True, timeout=120
    )
    assert typo.returncode == 2 and "nothing to resume" in typo.stderr and not Path(out).exists(), typo.stderr
    first = subprocess.run([*ARENA, *args, "--out", out, "--json"], capture_output=True, text=True, timeout=120)
    assert first.returncode == 0, first.stderr
    again = subprocess.run(
        [*ARENA, *args, "--out", out, "--resume", "--json"], capture_output=True, text=True, timeout=120
    )
    assert f"--resume: 2 of 2 matches kept from {out}" in again.stderr
    assert json.loads(again.stdout)["skipped"] == 2


def test_docs_explain_every_key_of_the_json(tmp_path):
    from pathlib import Path

    args = ("tournament", "--strategies", "BS,AD", "--legs", "1", "--half-time", "1", "--jobs", "1", *INPROCESS[:2])
    summary = arena_json(*args, "--out", str(tmp_path / "t"))
    doc = (Path(__file__).parents[2] / "docs" / "tournament.md").read_text()
    tables = doc.split("### The keys of `tournament.json`", 1)[1].split("\n## ", 1)[0]
    keys = [*summary, *summary["matches"][0]]
    assert [k for k in keys if f"`{k}`" not in tables] == [], "add them to docs/tournament.md"
