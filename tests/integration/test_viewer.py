"""The live viewer (processes/viewer.py) over the real Foxglove WebSocket protocol.

The client (foxglove_client.py) speaks the protocol itself on `websockets`.
Each match leaves robot a/1 to be started by the test (`--external`), so the
client is connected and subscribed before the first tick: nothing it should
count can pass before it listens.
"""

from __future__ import annotations

import json
import subprocess

from tests.integration.foxglove_client import FoxgloveClient, log_entry, scene_entities
from tests.integration.helpers import ARENA, free_ports, spawn, wait_until_joined

ROBOTS = {f"robot/{t}/{n}" for t in "ab" for n in range(3)}


def start_live(reap: list, match: str, *flags: str):
    """`arena match ... --live PORT --external a/1` in the background; returns (popen, ws url, start robot a/1,
    the match's router endpoint).

    Both processes go on `reap` (conftest.py), which kills and reaps what a failed test left running."""
    port, zport = free_ports(2)
    endpoint = f"tcp/127.0.0.1:{zport}"
    argv = [*ARENA, "match", "--home", "BS", "--away", "BS", "--live", str(port), "--external", "a/1"]
    argv += ["--match", match, "--listen", endpoint, "--json", *flags]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    reap.append(proc)
    # The robot is started with the command the match prints (with its credentials in a secure match).
    said = []
    while not any("arena run robot" in line for line in said):
        line = proc.stderr.readline()
        assert line, "".join(said) + proc.stderr.read()
        said.append(line)
    robot_argv = [*ARENA, *next(x for x in said if "arena run robot" in x).split()[1:]]

    def start_robot() -> subprocess.Popen:
        reap.append(robot := subprocess.Popen(robot_argv, stderr=subprocess.DEVNULL))
        return robot

    return proc, f"ws://127.0.0.1:{port}", start_robot, endpoint


def connect(url: str, proc: subprocess.Popen) -> FoxgloveClient:
    """The client, or a failure that says what the match printed (a viewer that could not serve, say)."""
    try:
        return FoxgloveClient(url, timeout=60)
    except OSError as exc:
        proc.kill()
        _, said = proc.communicate(timeout=30)
        raise AssertionError(f"no Foxglove server at {url} ({exc}); the match said:\n{said[-3000:]}") from exc


def finish(proc: subprocess.Popen, robot: subprocess.Popen | None) -> dict:
    out, err = proc.communicate(timeout=120)
    if robot is not None:
        robot.wait(timeout=30)
    assert proc.returncode == 0, err[-3000:]
    return json.loads(out)


def test_live_realtime_match_streams_the_scene_and_one_log_per_referee_command(reap):
    # --secure: the viewer is the read-only `viewer` principal of the match's access control
    proc, url, start_robot, _ = start_live(reap, "viewer-rt", "--realtime", "--half-time", "3", "--secure")
    client = connect(url, proc)
    assert {"/scene", "/referee_log", "/match"} <= set(client.channels)
    assert client.channels["/scene"]["schemaName"] == "foxglove.SceneUpdate"
    client.subscribe("/scene", "/referee_log", "/match")
    robot = start_robot()
    full, beliefs, referee_logs, last_match = 0, set(), [], None
    for topic, _, payload in client.messages(60):
        if topic == "/scene":
            ids = set(scene_entities(payload))
            if {"field", "ball", "score"} | ROBOTS <= ids:
                full += 1
            beliefs |= {i.split("/")[0] for i in ids if i.startswith(("seen/", "p_ball/"))}
        elif topic == "/referee_log":
            entry = log_entry(payload)
            if entry["name"] == "referee":
                referee_logs.append(entry["message"])
        elif topic == "/match":
            last_match = json.loads(payload)
    client.close()
    result = finish(proc, robot)
    assert result["realtime"] and result["ticks"] == 300
    # 6 s of play at up to SCENE_HZ (30) updates a second from a viewer that runs behind the match's
    # processes (lower_priority): at least 4 a second come through, as 40 in 10 s did
    assert full >= 24, f"only {full} complete scene updates"
    assert beliefs == {"seen", "p_ball"}, "the robots' perceived ball and the base stations' P_ball are drawn"
    commands = sum(result["events"].values())
    assert len(referee_logs) == commands, (referee_logs, result["events"])
    assert [m.split()[0] for m in referee_logs].count("KICKOFF") == result["events"]["KICKOFF"]
    assert last_match is not None and [last_match["score_a"], last_match["score_b"]] == result["score"]
    assert last_match["stage"] == "END_GAME"


def tick_of(payload: bytes) -> int:
    return json.loads(payload)["tick"]


def test_pause_step_resume_over_the_protocol_keeps_the_digest(reap):
    # The reference plays meanwhile: the live match stands paused most of the time.
    reference = spawn("match", "--home", "BS", "--away", "BS", "--half-time", "2", "--seed", "5", "--json")
    reap.append(reference)
    proc, url, start_robot, endpoint = start_live(
        reap, "viewer-pause", "--half-time", "2", "--seed", "5", "--pace", "0"
    )
    client = connect(url, proc)
    assert "parameters" in client.info["capabilities"]
    client.subscribe("/match")
    client.set_parameters(paused=True)
    held = [tick_of(p) for _, _, p in client.messages(60, until=lambda: client.parameters.get("paused") is True)]
    assert client.parameters.get("paused") is True, "the viewer answered the pause"
    robot = start_robot()
    wait_until_joined(endpoint, "viewer-pause", "robot/a/1")  # the match starts, and holds before tick 0
    held += [tick_of(p) for _, _, p in client.messages(1.0)]  # unpaced, a match that plays shows ticks at once
    assert held == [], f"the engine played while paused: {held[-3:]}"
    client.set_parameters(step=10)  # ticks 0..9
    stepped = []
    for _, _, p in client.messages(60):
        stepped.append(tick_of(p))
        if stepped[-1] >= 9:
            break
    stepped += [tick_of(p) for _, _, p in client.messages(1.0)]  # and no tick after 9 comes
    assert stepped and max(stepped) == 9, stepped[-5:]
    assert client.parameters.get("paused") is True
    client.set_parameters(paused=False)
    after = [tick_of(p) for _, _, p in client.messages(60)]
    client.close()
    result = finish(proc, robot)
    out, err = reference.communicate(timeout=120)
    assert reference.returncode == 0, err[-3000:]
    reference = json.loads(out)
    # unpaced, the viewer shows at most SCENE_HZ frames a second, and a late world frame may be dropped
    assert after and 10 < after[-1] <= result["ticks"] == reference["ticks"]
    assert result["digest"] == reference["digest"]
    assert result["process_digests"] == reference["process_digests"]
