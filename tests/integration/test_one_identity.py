"""Issues 34 and 36: one identity, one process; a robot without its file is refused at connect, not
told it forged; no secret outlives a killed launcher."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from tests.integration.helpers import ARENA, descendants, free_port, spawn, wait_for

GAME = ("match", "--home", "BS", "--away", "BS", "--half-time", "2", "--seed", "2", "--json")


def _printed(match: subprocess.Popen) -> list[str]:
    """The command the match prints for its one external process."""
    assert "external" in wait_for(lambda: match.stderr.readline(), 60, "the instructions")
    return match.stderr.readline().split()


def test_a_robot_started_before_the_match_without_its_file_is_refused_at_connect(tmp_path, reap):
    sock = f"unixsock-stream/{tmp_path}/r.sock"
    early = subprocess.Popen(
        [*ARENA, "run", "robot", "--match", "early", "--team", "a", "--robot", "1", "--connect", sock],
        stderr=subprocess.PIPE,
        text=True,
    )
    reap.append(early)
    assert "waiting: no router at" in early.stderr.readline()
    match = spawn(*GAME, "--external", "a/1", "--match", "early", "--listen", sock)
    reap.append(match)
    command = _printed(match)
    err = early.communicate(timeout=60)[1]
    assert early.returncode == 2, err
    assert err.strip().splitlines()[-1] == (
        "arena run: error: refused by match 'early': match 'early' needs robot/a/1's own --credentials file "
        "(every frame of its processes is authenticated): start it with the command arena match printed"
    )
    # A typo in --match is told with the match the router does host. It waits out its 2 s while
    # a second engine started by hand (the match's own is running) is refused too (issue 36).
    typo = subprocess.Popen(
        [*ARENA, "run", "robot", "--match", "eraly", "--team", "a", "--robot", "1", "--connect", sock]
        + ["--startup-timeout", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    reap.append(typo)
    engine = subprocess.run(
        [*ARENA, "run", "engine", "--match", "early", "--connect", sock, "--home", "BS", "--away", "BS"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    typo_err = typo.communicate(timeout=120)[1]
    assert typo.returncode == 2, typo_err
    assert typo_err.strip().splitlines()[-1] == (
        f"arena run: error: gave up after 2 s waiting for match 'eraly' to start at {sock}; "
        "the router hosts match 'early'"
    ), typo_err
    assert engine.returncode == 2, engine.stderr
    assert "engine is already running in match 'early' (started by arena match, pid" in engine.stderr, engine.stderr
    robot = subprocess.run([*ARENA, *command[1:]], capture_output=True, text=True, timeout=120)
    assert robot.returncode == 0, robot.stderr
    out, err = match.communicate(timeout=120)
    assert match.returncode == 0, err
    result = json.loads(out)
    assert result["outcome"] == "completed" and result["rejected"] == 0, result["rejected_reasons"]
    assert result["forged_summaries"] == {} and "forged" not in err, err
    refused, second_engine = result["refused_starts"]
    assert refused["process"] == "robot/a/1" and refused["from"].endswith(f"pid {early.pid}"), refused
    assert second_engine["process"] == "engine", result["refused_starts"]


def test_the_next_match_removes_what_a_killed_launcher_left(tmp_path, reap):
    env = {**os.environ, "TMPDIR": str(tmp_path)}  # its own temp dir: only this test's matches there
    port = free_port()
    match = subprocess.Popen(
        [*ARENA, *GAME, "--external", "a/1", "--secure", "--listen", f"tcp/127.0.0.1:{port}"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    reap.append(match)
    command = _printed(match)
    left = Path(command[command.index("--credentials") + 1]).parents[1]
    assert (left / "router-users.txt").exists() and (left / "credentials" / "robot-a-1.json5").exists()
    for pid in [*descendants(match.pid), match.pid]:
        os.kill(pid, signal.SIGKILL)
    match.communicate(timeout=30)
    time.sleep(0.5)
    assert (left / "router-users.txt").exists(), "kill -9 leaves it (nothing can run after it)"
    nxt = subprocess.run([*ARENA, *GAME, "--half-time", "1"], capture_output=True, text=True, timeout=120, env=env)
    assert nxt.returncode == 0, nxt.stderr
    assert not left.exists(), sorted(left.iterdir())
    assert list(tmp_path.glob("arena-*")) == [], "and the next match left nothing either"


def test_a_second_referee_with_the_matchs_own_credentials_file_is_refused(tmp_path, reap):
    """The file of a process arena match started (from its private temp dir) says `launched`, and a
    second referee started with it played on and voided the match. Now it is refused, with and
    without the match's own --config, and the match completes."""
    sock = f"unixsock-stream/{tmp_path}/r.sock"
    match = spawn(*GAME, "--external", "a/1", "--match", "own", "--listen", sock)
    reap.append(match)
    command = _printed(match)  # the match waits for robot a/1 meanwhile
    creds = Path(command[command.index("--credentials") + 1]).parent
    second = [
        *ARENA,
        "run",
        "referee",
        "--match",
        "own",
        "--connect",
        sock,
        "--credentials",
        str(creds / "referee.json5"),
    ]
    for extra in ([], ["--config", str(creds.parent / "config.json")]):
        r = subprocess.run([*second, *extra], capture_output=True, text=True, timeout=120)
        assert r.returncode == 2, r.stderr
        assert "referee is already running in match 'own'" in r.stderr.strip().splitlines()[-1], r.stderr
    robot = subprocess.run([*ARENA, *command[1:]], capture_output=True, text=True, timeout=120)
    assert robot.returncode == 0, robot.stderr
    out, err = match.communicate(timeout=120)
    assert match.returncode == 0, err
    result = json.loads(out)
    assert result["outcome"] == "completed" and result["faults"] == [], result["outcome_reasons"]
    assert [r["process"] for r in result["refused_starts"]] == ["referee", "referee"], result["refused_starts"]


def _twins(kind: list[str], secure: bool, tmp_path, reap, run: int) -> dict:
    """A match with one external process, started twice at the same moment; the match's result."""
    listen = (
        ["--secure", "--listen", f"tcp/127.0.0.1:{free_port()}"]
        if secure
        else ["--listen", f"unixsock-stream/{tmp_path}/r{run}.sock"]
    )
    external = "a/1" if kind[0] == "robot" else "basestation/b"
    match = spawn(*GAME, "--external", external, "--match", f"twins{run}", *listen)
    reap.append(match)
    command = _printed(match)
    twins = [subprocess.Popen([*ARENA, *command[1:]], stderr=subprocess.PIPE, text=True) for _ in range(2)]
    reap.extend(twins)
    errs = [t.communicate(timeout=120)[1] for t in twins]
    codes = sorted(t.returncode for t in twins)
    assert codes == [0, 2], errs
    loser = errs[[t.returncode for t in twins].index(2)]
    assert "is already running in match" in loser.strip().splitlines()[-1], loser
    out, err = match.communicate(timeout=120)
    assert match.returncode == 0, err
    return json.loads(out)


@pytest.mark.slow
@pytest.mark.parametrize("secure", [False, True], ids=["plain", "secure"])
@pytest.mark.parametrize("kind", [["robot"], ["basestation"]])
def test_of_two_simultaneous_starts_exactly_one_plays(kind, secure, tmp_path, reap):
    """5 runs per kind and mode (issue 36: before, both robots played in 4 of 4 runs)."""
    for run in range(5):
        result = _twins(kind, secure, tmp_path, reap, run)
        assert result["outcome"] == "completed" and result["rejected"] == 0, (run, result["rejected_reasons"])
        assert len(result["refused_starts"]) == 1, (run, result["refused_starts"])


def test_a_match_that_cannot_start_leaves_no_temp_dir(tmp_path):
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    r = subprocess.run(
        [*ARENA, *GAME, "--secure", "--logs", "/proc/no-logs-here"], capture_output=True, text=True, env=env, timeout=60
    )
    assert r.returncode == 2 and "/proc/no-logs-here" in r.stderr, r.stderr
    assert list(tmp_path.glob("arena-*")) == [], "its secrets stayed behind"


def test_arena_up_of_a_bad_compose_file_leaves_no_temp_dir(tmp_path):
    bad = tmp_path / "compose.yaml"
    bad.write_text("services: {router: {command: arena run engine --match x --listen tcp/127.0.0.1:1}}\n")
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    r = subprocess.run([*ARENA, "up", str(bad)], capture_output=True, text=True, env=env, timeout=60)
    assert r.returncode == 2, r.stderr
    assert list(tmp_path.glob("arena-*")) == [], "a temp dir for the credentials stayed behind"


@pytest.mark.parametrize("case", ["half time", "match typo"])
def test_arena_up_with_a_bad_half_time_or_a_match_typo_is_exit_2_and_leaves_nothing(case, tmp_path):
    """Both were exit 1 and kept a log directory in the temp dir: the engine refused ARENA_HALF_TIME
    after it had started, and a service with a typo in --match waited for a match that never came."""
    compose = Path(__file__).resolve().parents[2] / "compose.yaml"
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    if case == "half time":
        env["ARENA_HALF_TIME"] = "abc"
        needle = "arena up: error: service engine refused to start: argument --half-time: 'abc' is not a number"
    else:
        text = compose.read_text().replace(
            '"referee", "--match", "${ARENA_MATCH:-compose}"', '"referee", "--match", "compsoe"'
        )
        compose = tmp_path / "typo.yaml"
        compose.write_text(text)
        needle = "arena up: error: service 'referee': --match 'compsoe' is not the router's match"
    r = subprocess.run([*ARENA, "up", str(compose)], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.startswith(needle), r.stderr
    assert list(tmp_path.glob("arena-*")) == [], "a log directory stayed behind"
