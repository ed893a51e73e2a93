"""Hardware-in-the-loop (a robot started by hand), garbage on the wire, and `arena up compose.yaml`."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import msgspec
import zenoh

from arena.runtime.session import NetConfig, open_session
from arena.schemas.messages import Cmd, Report, encode
from tests.integration.helpers import ARENA, arena_json, spawn, wait_for

REPO = Path(__file__).resolve().parents[2]


def test_a_robot_started_by_hand_plays_its_part(tmp_path, reap):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    match = spawn(
        "match", "--home", "BS", "--away", "BS", "--half-time", "20", "--seed", "4",
        "--external", "a/1", "--match", "hil", "--listen", endpoint, "--json",
    )
    reap.append(match)
    # The launcher says how to start the missing robot; start it exactly so,
    # with no configuration file: it asks the engine for the match's.
    line = wait_for(lambda: match.stderr.readline(), 30, "the launcher's instructions")
    assert "external" in line
    command = match.stderr.readline().split()
    assert command[:3] == ["arena", "run", "robot"]
    robot = subprocess.Popen([*ARENA, *command[1:]], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    reap.append(robot)
    out, err = match.communicate(timeout=240)
    assert match.returncode == 0, err
    r_out, r_err = robot.communicate(timeout=30)
    assert robot.returncode == 0, r_err
    result = json.loads(out)
    a1 = next(p for p in result["processes"] if (p["kind"], p["team"], p["robot"]) == ("robot", "a", 1))
    assert a1["external"] and a1["pid"] == robot.pid
    assert result["distance_m"]["a/1"] > 0.5, "the hand-started robot moved"
    assert result["rejected"] == 0 and result["dead"] == []


def test_garbage_on_a_robots_cmd_key_is_rejected_and_the_match_goes_on(tmp_path, reap):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    logs = tmp_path / "logs"
    match = spawn(
        "match", "--home", "BS", "--away", "BS", "--half-time", "20", "--seed", "5",
        "--match", "noisy", "--listen", endpoint, "--json", "--logs", str(logs),
    )
    reap.append(match)
    wait_for(lambda: Path(endpoint.split("/", 1)[1]).exists(), 30, "the router socket")
    key = "arena/noisy/robot/a/1/cmd"
    bad = [
        b"\xde\xad\xbe\xef",  # not msgpack
        b"",  # empty
        msgspec.msgpack.encode({"tick": "soon", "vx": 1.0}),  # wrong type
        msgspec.msgpack.encode([1, 2, 3]),  # not a map
        encode(Report(tick=0, robot=1, pose={"x": 0, "y": 0, "theta": 0})),  # another message type (no tick order)
        msgspec.msgpack.encode({"tick": 999_999, "vx": float("nan")}),  # out of sequence
    ]
    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        # Wait until the match is being played: the referee has sent a frame.
        referee = session.declare_subscriber("arena/noisy/referee", zenoh.handlers.FifoChannel(1000))
        wait_for(lambda: referee.try_recv(), 60, "the match to start")
        pub = session.declare_publisher(key, congestion_control=zenoh.CongestionControl.BLOCK)
        for payload in bad * 5:
            pub.put(payload)
        referee.undeclare()
        out, err = match.communicate(timeout=240)
    assert match.returncode == 0, err
    result = json.loads(out)
    assert result["rejected"] >= len(bad) * 5 - 5, result["rejected_reasons"]
    assert result["rejected_reasons"].get("malformed", 0) >= 4 * 5
    log = (logs / "engine.log").read_text()
    assert "rejected input on arena/noisy/robot/a/1/cmd: malformed" in log
    assert "out-of-sequence" in log
    assert result["events"]["END_GAME"] == 1 and result["ticks"] == 2000


def test_arena_up_runs_the_compose_file_as_local_processes():
    env = dict(os.environ, ARENA_HALF_TIME="3", ARENA_SEED="2")
    r = arena_json("up", str(REPO / "compose.yaml"), env=env, timeout=240)
    assert r["services"][0] == "router" and len(r["services"]) == 11
    assert len({p["pid"] for p in r["processes"]}) == 10
    assert r["seed"] == 2 and r["half_time"] == 3.0 and r["link"] == "wifi"
    assert r["events"]["END_GAME"] == 1
