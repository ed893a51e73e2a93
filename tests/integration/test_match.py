"""`arena match` end to end: separate live processes, determinism, links, real time."""

from __future__ import annotations

import json
import time

import pytest

from arena.config import MatchConfig
from arena.match.inprocess import play_in_process
from arena.runtime.links import PRESETS
from tests.integration.helpers import arena_json, cmdline, descendants, spawn, wait_for

BASE = ("match", "--home", "basic-static", "--away", "basic-static", "--half-time", "30")


@pytest.fixture(scope="module")
def seed7_logs(tmp_path_factory):
    return tmp_path_factory.mktemp("seed7-logs")


@pytest.fixture(scope="module")
def seed7_watched(seed7_logs):
    """The seed-7 match, every process's log kept, with /proc watched while it runs:
    (its JSON, the `arena run` pids seen alive at once, their kinds)."""
    proc = spawn(*BASE, "--seed", "7", "--logs", str(seed7_logs), "--json")
    try:

        def running():
            pids = {p for p in descendants(proc.pid) if " -m arena run " in cmdline(p)}
            return pids if len(pids) == 10 else None

        seen = wait_for(running, 60, "ten live `arena run` processes")
        kinds = sorted(cmdline(p).split(" -m arena run ")[1].split()[0] for p in seen)
        out, err = proc.communicate(timeout=240)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    return json.loads(out), seen, kinds


@pytest.fixture(scope="module")
def seed7(seed7_watched):
    return seed7_watched[0]


def test_a_clean_match_logs_no_traceback(seed7, seed7_logs):
    """Not even at the end, when peers leave while others are closing (a liveliness callback once raced the close)."""
    logs = sorted(seed7_logs.glob("*.log"))
    assert len(logs) == 10
    for log in logs:
        assert "Traceback" not in log.read_text(), f"{log.name}:\n{log.read_text()[-2000:]}"


def test_every_process_is_its_own_live_os_process(seed7_watched):
    """Watch /proc while the match runs: ten `arena run` processes, all alive at once."""
    result, seen, kinds = seed7_watched
    reported = {p["pid"] for p in result["processes"]}
    assert reported == seen, "the JSON's pids are the processes seen running"
    assert kinds == ["basestation"] * 2 + ["engine", "referee"] + ["robot"] * 6


def test_acceptance_command_reports_the_contract(seed7):
    r = seed7
    assert r["seed"] == 7 and len(r["score"]) == 2
    assert r["ticks"] == 3000 and r["sim_seconds"] == pytest.approx(60.0)
    assert r["rtf"] > 1 and r["wall_seconds"] > r["play_wall_seconds"] > 0
    kinds = [(p["kind"], p["team"], p["robot"]) for p in r["processes"]]
    assert kinds[:4] == [
        ("engine", None, None),
        ("referee", None, None),
        ("basestation", "a", None),
        ("basestation", "b", None),
    ]
    assert sorted(k for k in kinds if k[0] == "robot") == [("robot", t, n) for t in "ab" for n in range(3)]
    assert len({p["pid"] for p in r["processes"]}) == 10
    for name in ("KICKOFF", "HALF_TIME", "SECOND_HALF", "END_GAME"):
        assert r["events"].get(name, 0) >= 1
    assert set(r["distance_m"]) == {f"{t}/{n}" for t in "ab" for n in range(3)}
    assert all(d > 0 for d in r["distance_m"].values())
    assert r["rejected"] == 0 and r["dead"] == []
    assert set(r["links"]) == {"sensor", "wifi", "wired"}
    assert all(link["dropped"] == 0 for link in r["links"].values()), "ideal drops nothing"


def test_the_readme_explains_every_key_of_the_json(seed7):
    from pathlib import Path

    readme = (Path(__file__).parents[2] / "README.md").read_text()
    table = readme.split("### What `arena match --json` reports", 1)[1].split("\n\n", 2)[1]
    assert [k for k in seed7 if f"`{k}`" not in table] == [], "add them to README's table"


def test_same_seed_same_digest_other_seed_other_digest(seed7):
    again = arena_json(*BASE, "--seed", "7")
    assert again["digest"] == seed7["digest"]
    assert again["score"] == seed7["score"]
    other = arena_json(*BASE, "--seed", "8")
    assert other["digest"] != seed7["digest"]


def test_processes_compute_exactly_what_one_process_computes(seed7):
    """The transport does not matter: the in-memory run gives the same per-process digests."""
    summaries, _ = play_in_process(MatchConfig(seed=7, half_time=30.0), watch=())
    assert {name: s.digest for name, s in summaries.items()} == seed7["process_digests"]


def test_congested_wifi_drops_at_the_preset_rate(seed7):
    r = arena_json(*BASE, "--seed", "7", "--link", "congested-wifi")
    wifi = r["links"]["wifi"]
    expected = PRESETS["congested-wifi"]["wifi"].stationary_loss()
    assert wifi["dropped"] > 0
    assert wifi["drop_rate"] == pytest.approx(expected, rel=0.30)
    assert wifi["delay_ms_mean"] > 15.0
    assert r["links"]["sensor"]["dropped"] == 0
    assert r["digest"] != seed7["digest"]


def test_realtime_paces_to_the_wall_clock():
    """4 s of play, held to the same 20 % (0.8 s either way): an unpaced match (200 ticks take well
    under a second) fails, as does one paced more than 20 % too fast or too slow."""
    t0 = time.monotonic()
    r = arena_json("match", "--home", "BS", "--away", "BS", "--realtime", "--half-time", "2", "--seed", "1")
    wall = time.monotonic() - t0
    assert r["ticks"] == 200 and r["sim_seconds"] == pytest.approx(4.0)
    assert r["play_wall_seconds"] == pytest.approx(4.0, rel=0.20)
    assert r["rtf"] == pytest.approx(1.0, rel=0.20)
    assert wall < 4.0 * 1.2 + 6.0, "start-up should add seconds, not more"
    assert r["events"]["END_GAME"] == 1
