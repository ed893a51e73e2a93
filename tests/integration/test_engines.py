"""`--engine inprocess` against `--engine processes`: the same digests, the same recording.

A sample of what the acceptance compares in full (the 60-match tournament):
several seeds on two link presets, through `arena tournament` with each
engine, and one recorded match whose MCAP message records must be equal.
Short half-times keep it to seconds.
"""

from __future__ import annotations

import subprocess

import pytest

from tests.integration.helpers import ARENA, arena_json
from tests.unit.test_recording import records_in_file_order

SAMPLE = ("tournament", "--strategies", "AD,BS,chase", "--legs", "1", "--half-time", "2", "--seed", "11")


@pytest.mark.parametrize("link", ["ideal", "congested-wifi"])
def test_both_engines_give_the_same_digests_in_a_tournament(tmp_path, link):
    runs = {}
    for engine in ("processes", "inprocess"):
        out = tmp_path / engine
        runs[engine] = arena_json(*SAMPLE, "--link", link, "--engine", engine, "--out", str(out))
        assert runs[engine]["engine"] == engine
        assert {m["engine"] for m in runs[engine]["matches"]} == {engine}
    a, b = ({m["id"]: (m["status"], m["digest"], m["score"]) for m in runs[e]["matches"]} for e in runs)
    assert len(a) == 3 and len({d for _, d, _ in a.values()}) == 3, "three different matches"
    assert a == b
    assert runs["processes"]["table"] == runs["inprocess"]["table"]


def test_a_recorded_inprocess_match_has_the_same_records_and_digests(tmp_path):
    base = ("match", "--home", "AD", "--away", "BS", "--half-time", "3", "--seed", "6", "--link", "wifi")
    rec = {e: tmp_path / f"{e}.mcap" for e in ("processes", "inprocess")}
    got = {e: arena_json(*base, "--engine", e, "--record", str(rec[e])) for e in rec}
    assert got["inprocess"]["engine"] == "inprocess"
    assert got["processes"]["process_digests"] == got["inprocess"]["process_digests"]
    assert got["processes"]["recording"]["messages"] == got["inprocess"]["recording"]["messages"]
    # The link counters too: only the frames the receivers waited for, never those racing the end.
    assert got["processes"]["links"] == got["inprocess"]["links"]
    assert got["inprocess"]["recording"]["complete"] is True
    records = {e: records_in_file_order(rec[e]) for e in rec}
    assert len(records["processes"]) > 1000
    assert records["processes"] == records["inprocess"]


@pytest.mark.parametrize(
    ("flag", "value"),
    [("--realtime", None), ("--external", "a/1"), ("--listen", "tcp/127.0.0.1:0"), ("--logs", "/tmp")],
)
def test_inprocess_refuses_what_needs_processes_in_one_line(flag, value):
    args = ["match", "--home", "BS", "--away", "BS", "--engine", "inprocess", flag] + ([value] if value else [])
    r = subprocess.run([*ARENA, *args], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "needs --engine processes" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


@pytest.mark.parametrize("latency", [3, 16])
def test_a_batched_distributed_match_has_the_digests_of_one_frame_per_message(latency):
    """L ticks of sense/cmd frames per zenoh message, against one per message in one process.

    16: more than the referee's and the base stations' slack, which deadlocked until
    a process put its held-back batch whenever it was about to wait."""
    base = ("match", "--home", "AD", "--away", "BS", "--half-time", "2", "--seed", "3")
    base = (*base, "--perception-latency", str(latency))
    batched = arena_json(*base)  # --engine processes, --batch 0: L frames per message
    single = arena_json(*base, "--engine", "inprocess", "--batch", "1")
    assert batched["outcome"] == "completed" and batched["rejected"] == 0
    assert batched["process_digests"] == single["process_digests"]


def test_a_strategy_parameter_changes_the_digest_alike_on_both_engines():
    base = ("match", "--home", "AD", "--away", "BS", "--half-time", "20", "--seed", "1", "--json")
    plain = arena_json(*base, "--engine", "inprocess")
    got = {e: arena_json(*base, "--engine", e, "--param", "a.kick_speed=6.0") for e in ("processes", "inprocess")}
    assert got["processes"]["digest"] == got["inprocess"]["digest"] != plain["digest"]
    assert got["processes"]["process_digests"] == got["inprocess"]["process_digests"]
    assert got["processes"]["params"] == got["inprocess"]["params"] == {"a": {"kick_speed": 6.0}}
