"""A match survives a crashed robot, an invalid frame never stalls it, and a broken match never exits 0.

Real processes over real zenoh: the faults are real signals (kill -9,
SIGSTOP/SIGCONT) sent to real children at a tick read off the wire, and the
NaN strategy is a real plugin found through its entry point by every process.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import msgspec
import pytest
import zenoh

from arena.recording.reader import load
from arena.review.review import print_review
from arena.runtime.session import NetConfig, open_session
from arena.schemas.messages import Referee, World
from tests.integration.helpers import ARENA, alive, arena_in_process, cmdline, descendants, spawn, wait_for

MATCH = ("match", "--home", "BS", "--away", "BS", "--json")


def child(launcher_pid: int, needle: str) -> int:
    """The pid of the match process whose command line contains `needle`."""

    def find():
        return next((p for p in descendants(launcher_pid) if needle in cmdline(p)), None)

    return wait_for(find, 60, f"a process with {needle!r}")


def wait_for_tick(endpoint: str, match: str, tick: int, proc) -> int:
    """Block until the referee has sent a frame for `tick` or later; returns that frame's tick."""
    decode = msgspec.msgpack.Decoder(Referee).decode
    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        sub = session.declare_subscriber(f"arena/{match}/referee", zenoh.handlers.FifoChannel(10000))
        seen = [-1]

        def reached():
            assert proc.poll() is None, "the match ended before the tick"
            while (s := sub.try_recv()) is not None:
                seen[0] = decode(s.payload.to_bytes()).tick
            return seen[0] >= tick

        wait_for(reached, 120, f"tick {tick}", interval=0.005)
        sub.undeclare()
    return seen[0]


def finish(proc, timeout: float = 300) -> tuple[int, dict | None, str]:
    out, err = proc.communicate(timeout=timeout)
    return proc.returncode, (json.loads(out) if out.strip() else None), err


def test_kill_9_of_a_robot_is_a_fault_and_its_team_plays_on(reap, tmp_path, capfd):
    """Issue 15 acceptance: kill -9 of robot b/1 at about tick 1500 of a recorded 2 x 60 s match."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    mcap = tmp_path / "crash.mcap"
    proc = spawn(*MATCH, "--half-time", "60", "--seed", "4", "--match", "crash", "--listen", endpoint,
                 "--record", str(mcap))  # fmt: skip
    reap.append(proc)
    victim = child(proc.pid, "--team b --robot 1")
    at = wait_for_tick(endpoint, "crash", 1500, proc)
    os.kill(victim, signal.SIGKILL)
    code, result, err = finish(proc)
    assert code == 0, err
    assert result["outcome"] == "completed_with_faults" and not result["void"]
    assert result["ticks"] == 6000 and result["events"]["END_GAME"] == 1
    assert result["dead"] == ["robot/b/1"]
    [fault] = result["faults"]
    assert fault["process"] == "robot/b/1" and "code -9" in fault["reason"]
    # The referee may run a few ticks ahead of the engine (its links have lag 1 and it sends every 5th
    # tick), so the engine can notice the crash at a tick just below the referee frame the test saw.
    assert at - 10 <= fault["tick"] <= at + 500, (at, fault)
    assert "fault: robot/b/1 at tick" in err and "Traceback" not in err
    parked = result["parked"]["b/1"]
    assert fault["tick"] <= parked["tick"] <= fault["tick"] + 1
    assert result["distance_m"]["b/2"] > 5, "its team plays on"
    # A fault's logs are kept for the user to read, but no secret is left with them (issue 36).
    kept = Path(result["logs"])
    assert (kept / "robot_b_1.log").exists(), sorted(kept.iterdir())
    assert not (kept / "credentials").exists() and not (kept / "router-users.txt").exists(), sorted(kept.iterdir())

    # The ground truth in the recording: from its parking on, robot b/1 stands still
    # beyond the fence, and neither the ball nor any robot ever comes near it.
    rec = load(str(mcap))
    cfg = rec.cfg
    fence_x = cfg.field.length / 2 + cfg.field.runoff
    reach = cfg.robot.size  # centre to centre: two robots' half sizes, or a robot's and more than a ball's
    after = [w for w in rec.decoded("world", World) if w.tick > parked["tick"]]
    assert len(after) > 4000
    for w in after:
        me = next(r for r in w.robots if (r.team, r.robot) == ("b", 1))
        assert (round(me.x, 3), round(me.y, 3)) == (parked["x"], parked["y"]) and abs(me.x) > fence_x
        assert math.hypot(w.ball_x - me.x, w.ball_y - me.y) > reach, w.tick
        for r in w.robots:
            if r is not me:
                assert math.hypot(r.x - me.x, r.y - me.y) > reach, (w.tick, r)
    # `arena review` analysed once, in this process (its real processes: tests/integration/test_recording.py);
    # its text mode prints that same analysis with `print_review` (review/review.py `main`).
    review = arena_in_process(["review", str(mcap), "--json"], capfd)
    assert review.returncode == 0, review.stderr
    reviewed = json.loads(review.stdout)
    faults = reviewed["faults"]
    assert [f["process"] for f in faults] == ["robot/b/1"] and abs(faults[0]["tick"] - fault["tick"]) <= 1
    print_review(reviewed)
    assert "fault: robot/b/1 at" in capfd.readouterr().out


@pytest.mark.slow
def test_strict_stops_the_match_at_the_first_crash(reap, tmp_path):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    proc = spawn(*MATCH, "--half-time", "60", "--seed", "3", "--match", "strict", "--listen", endpoint, "--strict")
    reap.append(proc)
    victim = child(proc.pid, "--team a --robot 2")
    wait_for_tick(endpoint, "strict", 100, proc)
    os.kill(victim, signal.SIGKILL)
    code, result, err = finish(proc, 60)
    assert code == 1 and result is None
    assert f"robot/a/2 (pid {victim}) exited with code -9" in err


def test_a_dead_referee_voids_the_match_at_once(reap, tmp_path):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    proc = spawn(*MATCH, "--half-time", "60", "--seed", "3", "--match", "noref", "--listen", endpoint)
    reap.append(proc)
    victim = child(proc.pid, "arena run referee")
    kids = descendants(proc.pid)
    at = wait_for_tick(endpoint, "noref", 200, proc)
    os.kill(victim, signal.SIGKILL)
    code, result, err = finish(proc, 60)
    assert code == 1
    assert result["void"] and result["outcome"] == "void"
    # Issue 36: what was played, not `ticks: 0, score [0, 0]`: as far as the referee's last frame.
    assert at <= result["ticks"] < 6000 and result["sim_seconds"] == round(result["ticks"] * 0.02, 3)
    assert len(result["score"]) == 2 and all(isinstance(n, int) for n in result["score"])
    assert "referee exited with code -9 (SIGKILL)" in result["outcome_reasons"][0]
    assert err.strip().splitlines()[-1].startswith("arena match: void: referee exited with code -9")
    wait_for(lambda: not [p for p in kids if alive(p)], 10, "every process of the void match to stop")


@pytest.mark.slow
def test_a_dead_engine_voids_the_match(reap, tmp_path):
    """Issue 20: kill -9 of the engine used to leave the others playing to the end and exit 0."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    proc = spawn(*MATCH, "--half-time", "60", "--seed", "3", "--match", "noengine", "--listen", endpoint)
    reap.append(proc)
    victim = child(proc.pid, "arena run engine")
    wait_for_tick(endpoint, "noengine", 200, proc)
    os.kill(victim, signal.SIGKILL)
    code, result, err = finish(proc, 60)
    assert code == 1 and result["outcome"] == "void"
    assert any("engine exited with code -9" in r for r in result["outcome_reasons"])
    assert "arena match: void: engine exited with code -9" in err


NAN_PLUGIN = '''
import math
from arena.schemas.messages import Cmd
from arena.strategies import registry
from arena.strategies.base import Strategy

_BS = registry.get("BS")


class NanRobot:
    """The basic-static robot, but every 100th tick its command is NaN."""

    def __init__(self, ctx):
        self.inner = _BS.make_robot(ctx)

    def step(self, tick, sense, order):
        cmd = self.inner.step(tick, sense, order)
        if tick % 100 == 50:
            return Cmd(tick=tick, vx=math.nan, vy=cmd.vy, omega=math.inf)
        return cmd

    def report(self, tick, sense):
        return self.inner.report(tick, sense)


STRATEGY = Strategy(name="nan-every-100", make_team=_BS.make_team, make_robot=NanRobot)
'''


def nan_plugin(tmp_path) -> dict[str, str]:
    """An installed strategy plugin (a module and its dist-info on PYTHONPATH): the env to play it."""
    root = tmp_path / "plugin"
    dist = root / "nan_strategy-1.0.dist-info"
    dist.mkdir(parents=True)
    (root / "nan_strategy.py").write_text(textwrap.dedent(NAN_PLUGIN))
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: nan-strategy\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[soccer_arena.strategies]\nnan = nan_strategy:STRATEGY\n")
    path = os.pathsep.join(p for p in (str(root), os.environ.get("PYTHONPATH", "")) if p)
    return dict(os.environ, PYTHONPATH=path)


def test_a_strategy_that_returns_nan_every_100_ticks_plays_to_the_end(reap, tmp_path):
    """Issue 15 acceptance: 2 x 60 s to END_GAME, its invalid frames counted, no peer declared dead."""
    proc = spawn("match", "--home", "nan-every-100", "--away", "BS", "--half-time", "60", "--seed", "5", "--json",
                 env=nan_plugin(tmp_path))  # fmt: skip
    reap.append(proc)
    code, result, err = finish(proc)
    assert code == 0, err
    assert result["outcome"] == "completed", result["outcome_reasons"]
    assert result["ticks"] == 6000 and result["events"]["END_GAME"] == 1
    assert result["dead"] == [] and result["faults"] == []
    # Every robot of team a: one NaN command per 100 ticks, ticks 50, 150, ..., 5950.
    assert result["rejected_reasons"]["invalid"] == 3 * 60, result["rejected_reasons"]
    assert "out-of-sequence" not in result["rejected_reasons"]


def test_a_robot_stopped_beyond_its_lease_alone_is_blamed(reap, tmp_path):
    """Issue 20: SIGSTOP robot a/1 for 10 s. It used to list engine and basestation/a as dead too.

    10 s was 1.7 times the 6 s lease; here the match's `timing.lease` is 3 s (a --config file) and
    the robot is stopped for twice that, so every peer's lease on it expires well before it resumes."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    mcap = tmp_path / "stop10.mcap"
    config = tmp_path / "quick.toml"
    lease = 3.0
    config.write_text(f"[timing]\nlease = {lease}\n")
    proc = spawn(*MATCH, "--config", str(config), "--half-time", "60", "--seed", "3", "--match", "stop10",
                 "--listen", endpoint, "--record", str(mcap))  # fmt: skip
    reap.append(proc)
    victim = child(proc.pid, "--team a --robot 1")
    wait_for_tick(endpoint, "stop10", 1000, proc)
    os.kill(victim, signal.SIGSTOP)
    try:
        proc.wait(2 * lease)
    except subprocess.TimeoutExpired:
        pass
    os.kill(victim, signal.SIGCONT)
    code, result, err = finish(proc)
    assert code == 0, err
    assert result["dead"] == ["robot/a/1"], result["dead"]
    assert [f["process"] for f in result["faults"]] == ["robot/a/1"], result["faults"]
    assert result["outcome"] == "completed_with_faults" and result["ticks"] == 6000
    assert result["events"]["END_GAME"] == 1
    # The recording is complete with equal counts, or says what it lacks (it used to claim complete).
    rec = load(str(mcap))
    recorded = result["recording"]
    if recorded["complete"]:
        assert rec.complete and rec.gaps == {}
        sent = {k: n for k, n in result["sent_by_key"].items()}
        assert all(rec.counts.get(k, 0) == n for k, n in sent.items())
    else:
        assert not rec.complete and "robot/a/1" in rec.gaps, rec.gaps
        assert recorded["gaps"] == rec.gaps
        review = subprocess.run([*ARENA, "review", str(mcap)], capture_output=True, text=True, timeout=120)
        assert "gap: robot/a/1:" in review.stdout, review.stdout


@pytest.mark.slow
def test_a_killed_recorder_is_a_fault_and_its_file_stays_readable(reap, tmp_path):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    mcap = tmp_path / "cut.mcap"
    proc = spawn(*MATCH, "--half-time", "60", "--seed", "3", "--match", "norec", "--listen", endpoint,
                 "--record", str(mcap))  # fmt: skip
    reap.append(proc)
    victim = child(proc.pid, "arena run recorder")
    wait_for_tick(endpoint, "norec", 2000, proc)
    os.kill(victim, signal.SIGKILL)
    code, result, err = finish(proc)
    assert code == 0, err
    assert result["outcome"] == "completed_with_faults" and result["ticks"] == 6000
    assert [f["process"] for f in result["faults"]] == ["recorder"]
    assert result["recording"]["complete"] is False and "recorder failed" in result["recording"]["error"]
    rec = load(str(mcap))
    assert rec.truncated and not rec.complete
    assert len(rec.payloads("world")) > 500, "readable up to its last whole chunk"
    review = subprocess.run([*ARENA, "review", str(mcap), "--json"], capture_output=True, text=True, timeout=120)
    assert review.returncode == 0 and json.loads(review.stdout)["truncated"], review.stderr


NO_SUMMARY = """
import sys
import time
from arena.processes.robot import RobotNode
from arena.cli import main

# Plays every tick, then stays connected (its liveliness token stays) and never sends its Summary.
RobotNode.deliver_summary = lambda self, payload, timeout=5.0: time.sleep(120)
sys.exit(main(sys.argv[1:]))
"""


def test_an_external_robot_that_never_sends_its_summary_is_named_within_the_bound(reap, tmp_path):
    """Issue 20: `arena match` used to wait for it forever. The bound is `timing.finish_grace` (10 s by
    default), set shorter from a --config file."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    config = tmp_path / "quick.toml"
    config.write_text("[timing]\nfinish_grace = 2.0\n")
    proc = spawn(*MATCH, "--config", str(config), "--half-time", "10", "--seed", "4", "--match", "mute",
                 "--listen", endpoint, "--external", "a/1")  # fmt: skip
    reap.append(proc)
    # Start it with the command the launcher prints (its credentials included), through the patched main.
    line = ""
    while not line.strip().startswith("arena run robot"):
        line = wait_for(lambda: proc.stderr.readline(), 60, "the launcher's instructions")
    robot = subprocess.Popen([sys.executable, "-c", NO_SUMMARY, *line.split()[1:]],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
    reap.append(robot)
    code, result, err = finish(proc, 120)
    assert code == 0, err
    [fault] = result["faults"]
    assert fault["process"] == "robot/a/1" and "sent no summary within 2 s" in fault["reason"]
    assert result["outcome"] == "completed_with_faults" and result["ticks"] == 1000
    assert result["distance_m"]["a/1"] > 0.5, "it did play"
    assert "fault: robot/a/1" in err


def test_two_senders_on_one_key_are_flagged_as_possible_spoofing(reap, tmp_path):
    """Issue 15: a client answers every `sense` of robot b/1 with a forged `cmd` for the same tick.
    Issue 36: the frames carry no MAC of robot b/1, so the engine drops every one as forged (none
    takes a tick's slot, so none is a conflict) and the launcher says so during the match."""
    from arena.runtime.lockstep import BATCH_HEADS
    from arena.schemas.messages import Cmd, Sense, encode

    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    proc = spawn(*MATCH, "--half-time", "10", "--seed", "4", "--match", "spoof", "--listen", endpoint)
    reap.append(proc)
    decode = msgspec.msgpack.Decoder(Sense).decode

    def ticks(raw: bytes) -> list[int]:
        """The ticks of a `sense` message: one frame, or a batch of them (schemas/README.md, "Batches")."""
        frames = msgspec.msgpack.decode(raw) if raw[0] in BATCH_HEADS else [raw]
        return [decode(f).tick for f in frames]

    wait_for(lambda: (tmp_path / "router.sock").exists(), 30, "the router socket")
    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        pub = session.declare_publisher("arena/spoof/robot/b/1/cmd", congestion_control=zenoh.CongestionControl.DROP)
        forged = [0]

        def answer(sample):
            for tick in ticks(sample.payload.to_bytes()):
                pub.put(encode(Cmd(tick=tick, vx=-5.0, omega=3.0)))
                forged[0] += 1

        sub = session.declare_subscriber("arena/spoof/robot/b/1/sense", answer)
        code, result, err = finish(proc, 120)
        sub.undeclare()
    assert code == 0, err
    assert forged[0] > 100
    assert result["forged"].get("robot/b/1/cmd", 0) > 0, result["rejected_reasons"]
    assert result["rejected_reasons"]["forged"] == sum(result["forged"].values())
    assert result["conflicts"] == {}, "a forged frame never takes a tick's slot"
    assert err.count("possible spoofing on robot/b/1/cmd (forged or conflicting frames, seen by engine)") == 1, err
    assert "possible spoofing on robot/b/1/cmd (" in err


CAMPAIGN = [  # (the process to kill, its command-line marker, whether the match then counts)
    ("robot/a/2", "--team a --robot 2", True),
    ("basestation/b", "arena run basestation", True),
    ("referee", "arena run referee", False),
    ("engine", "arena run engine", False),
    ("recorder", "arena run recorder", True),
]


@pytest.mark.slow
@pytest.mark.parametrize(("process", "needle", "counts"), CAMPAIGN, ids=[c[0] for c in CAMPAIGN])
def test_fault_campaign_kill_9_at_a_seeded_random_tick(reap, tmp_path, process, needle, counts):
    """Issue 15, item 5: kill -9 of each kind of process at a seeded random tick of a recorded 2 x 60 s match."""
    import random

    tick = random.Random(f"campaign/{process}").randint(200, 5000)
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    proc = spawn(*MATCH, "--half-time", "60", "--seed", "7", "--match", "campaign", "--listen", endpoint,
                 "--record", str(tmp_path / "c.mcap"))  # fmt: skip
    reap.append(proc)
    if process == "basestation/b":
        victim = wait_for(
            lambda: next((p for p in descendants(proc.pid) if needle in cmdline(p) and "--team b" in cmdline(p)), None),
            60,
            "basestation/b",
        )
    else:
        victim = child(proc.pid, needle)
    wait_for_tick(endpoint, "campaign", tick, proc)
    os.kill(victim, signal.SIGKILL)
    code, result, err = finish(proc)
    assert "Traceback" not in err
    assert process in [f["process"] for f in result["faults"]], result["faults"]
    if process in ("referee", "engine"):
        assert code == 1 and result["outcome"] == "void", err
    else:
        assert code == 0, err
        assert result["outcome"] == "completed_with_faults" and result["ticks"] == 6000
        assert result["events"]["END_GAME"] == 1
    assert counts == (result["outcome"] != "void")
