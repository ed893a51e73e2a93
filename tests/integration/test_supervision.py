"""Isolation of concurrent matches, Ctrl-C and crashes: the whole group stops, nothing is orphaned."""

from __future__ import annotations

import json
import os
import re
import signal
import tempfile
from pathlib import Path

import pytest

from tests.integration.helpers import alive, cmdline, descendants, spawn, wait_for, wait_until_playing

MATCH = ("match", "--home", "BS", "--away", "BS", "--seed", "3", "--json")


def arena_children(pid: int) -> set[int]:
    return {p for p in descendants(pid) if " -m arena run " in cmdline(p)}


def all_ten(pid: int) -> set[int]:
    return wait_for(lambda: k if len(k := arena_children(pid)) == 10 else None, 60, "ten live processes")


def test_two_matches_at_once_do_not_hear_each_other(reap):
    """Same seed and even the same match id (key prefix): separate routers keep them apart."""
    a = spawn(*MATCH, "--half-time", "20", "--match", "twin")
    b = spawn(*MATCH, "--half-time", "20", "--match", "twin")
    reap.extend([a, b])
    out_a, err_a = a.communicate(timeout=300)
    out_b, err_b = b.communicate(timeout=300)
    assert a.returncode == 0, err_a
    assert b.returncode == 0, err_b
    ra, rb = json.loads(out_a), json.loads(out_b)
    assert ra["rejected"] == 0 and rb["rejected"] == 0, "a frame from the other match would be out of sequence"
    assert ra["dead"] == [] and rb["dead"] == []
    assert ra["digest"] == rb["digest"], "same seed, no cross-talk: the same match twice"
    assert {p["pid"] for p in ra["processes"]}.isdisjoint({p["pid"] for p in rb["processes"]})


def match_dirs() -> set[Path]:
    return set(Path(tempfile.gettempdir()).glob("arena-*"))


@pytest.mark.parametrize(
    ("sig", "code", "said"),
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")],
    ids=["ctrl-c", "sigterm"],
)
def test_ctrl_c_or_sigterm_stops_every_process(reap, sig, code, said):
    """SIGTERM (kill, a service manager) stops as Ctrl-C does; it used to leave the match's temp
    dir behind, its credentials included, and say nothing."""
    before = match_dirs()
    proc = spawn(*MATCH, "--half-time", "300")
    reap.append(proc)
    kids = all_ten(proc.pid)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == code, err
    assert err.strip().splitlines()[-1] == f"arena match: {said}; every process of the match was stopped", err
    assert "Traceback" not in err
    survivors = [p for p in kids if alive(p)]
    assert survivors == [], f"orphans: {survivors}"
    assert match_dirs() - before == set(), "an interrupted match leaves no temp dir behind"


def test_a_crashing_child_ends_a_strict_match_with_a_clear_message(reap):
    proc = spawn(*MATCH, "--half-time", "300", "--strict")
    reap.append(proc)
    kids = all_ten(proc.pid)
    victim = next(p for p in kids if "--team a --robot 2" in cmdline(p))
    os.kill(victim, signal.SIGKILL)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1
    assert f"robot/a/2 (pid {victim}) exited with code -9" in err
    assert "Traceback" not in err.splitlines()[0]
    wait_for(lambda: not [p for p in kids if alive(p)], 10, "every process of the match to stop")
    kept = re.search(r"every process's log is kept in (\S+)", err)
    assert kept, err
    assert (Path(kept.group(1)) / "robot_a_2.log").exists()


def test_a_killed_launcher_leaves_no_orphans(reap):
    proc = spawn(*MATCH, "--half-time", "300")
    reap.append(proc)
    kids = all_ten(proc.pid)
    proc.kill()
    proc.wait()
    wait_for(lambda: not [p for p in kids if alive(p)], 10, "the children to die with their launcher")


def test_a_hung_robot_is_declared_dead_after_a_bounded_wait(reap, tmp_path):
    """SIGSTOP a robot: its liveliness lease expires, and the match plays on without it.

    The bounds waited out are the match's own (`timing.lease`, 6 s by default, and the launcher's
    `timing.summary_grace`), set shorter from a --config file; the match is as long as the wait needs."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    config = tmp_path / "quick.toml"
    config.write_text("[timing]\nlease = 3.0\nsummary_grace = 1.0\n")
    proc = spawn(*MATCH, "--config", str(config), "--half-time", "6", "--match", "hang", "--listen", endpoint)
    reap.append(proc)
    kids = all_ten(proc.pid)
    wait_until_playing(endpoint, "hang")
    victim = next(p for p in kids if "--team b --robot 2" in cmdline(p))
    os.kill(victim, signal.SIGSTOP)
    out, err = proc.communicate(timeout=240)
    assert proc.returncode == 0, err
    result = json.loads(out)
    assert result["dead"] == ["robot/b/2"]
    assert result["events"]["END_GAME"] == 1 and result["ticks"] == 600
    # said when it happened, not only in the result
    assert "robot/b/2 stopped responding: its liveliness token vanished" in err and "the match plays on" in err, err
    wait_for(lambda: not alive(victim), 10, "the hung robot to be stopped")


def test_sigterm_stops_arena_facts_and_its_workers_now(reap):
    """SIGTERM reaches only the parent: its pool waited for every running match to end (a 2 x 3600 s
    match here), where Ctrl-C on a terminal reaches the workers too."""
    proc = spawn("facts", "--seeds", "2", "--half-time", "3600", "--home", "AD", "--away", "BS")
    reap.append(proc)
    workers = wait_for(
        lambda: w if len(w := {p for p in descendants(proc.pid) if "spawn_main" in cmdline(p)}) == 2 else None,
        60,
        "two workers playing",
    )
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert (
        err.strip().splitlines()[-1]
        == "arena facts: terminated; every match still playing was stopped, its worker with it"
    )
    wait_for(lambda: not [p for p in workers if alive(p)], 10, "the workers to be gone")
