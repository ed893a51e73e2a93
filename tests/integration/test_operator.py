"""The operator principal: `arena operator` (and the Foxglove Publish panel, through the live viewer)
teleports the ball and forces a referee command in a live session over real zenoh; the engine and the
referee apply them at a tick and log them."""

from __future__ import annotations

import json
import subprocess

import pytest

from arena.recording.reader import load
from arena.runtime.session import listening
from arena.schemas.messages import World
from tests.integration.helpers import ARENA, free_port, spawn, wait_for, wait_until_playing


def test_arena_operator_and_the_foxglove_publish_panel_drive_a_live_match(reap, tmp_path):
    from tests.integration.foxglove_client import FoxgloveClient, log_entry
    from tests.integration.test_fuzz import Launcher

    port, live, mcap = free_port(), free_port(), tmp_path / "op.mcap"
    endpoint = f"tcp/127.0.0.1:{port}"
    match = Launcher(
        reap, tmp_path / "logs", "match", "--home", "BS", "--away", "BS", "--realtime", "--half-time", "8",
        "--listen", endpoint, "--match", "op", "--live", str(live), "--record", str(mcap), "--json",
    )  # fmt: skip
    # The operator's credentials file (its MAC key), as arena match says where it is.
    said = match.line("operator: arena operator", 60).split()
    credentials = said[said.index("--credentials") + 1]
    client = FoxgloveClient(f"ws://127.0.0.1:{live}", timeout=60)
    assert "clientPublish" in client.info["capabilities"]
    client.subscribe("/referee_log")
    wait_until_playing(endpoint, "op")  # the engine listens from its start
    teleport = '{"type": "teleport_ball", "x": 3.3, "y": -2.2, "vx": 0, "vy": 0}'
    corner = '{"type": "referee", "command": "CORNER", "team": "b"}'
    op = subprocess.run(
        [*ARENA, "operator", "--match", "op", "--connect", endpoint, "--credentials", credentials, teleport, corner],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert op.returncode == 0 and "sent 2 action(s) to arena/op/operator" in op.stdout, op.stderr
    # The engine and the referee apply what they received at their next tick: the second teleport goes
    # once the viewer has logged the corner that came in the same message as the first, so that each
    # teleport has a tick, and a world frame, of its own.
    for _, _, entry in client.messages(30):
        if (said := log_entry(entry))["name"] == "referee" and said["message"].startswith("CORNER"):
            break
    else:
        raise AssertionError("the viewer never logged the corner `arena operator` forced")
    channel = client.advertise("/operator", "arena.Operator")
    client.publish(channel, b'{"actions": [{"type": "teleport_ball", "x": -3.3, "y": 2.2, "vx": 0, "vy": 0}]}')
    client.publish(channel, b'{"actions": [{"type": "teleport_bal"}]}')  # refused, counted
    client.close()
    out = match.finish(120)
    assert match.proc.returncode == 0, "".join(match.err)
    result = json.loads(out)
    assert result["events"].get("CORNER", 0) >= 1
    assert result["rejected"] >= 1 and any("malformed" in r for r in result["rejected_reasons"]), result
    rec = load(str(mcap))
    worlds = {w.tick: w for w in rec.decoded("world", World)}
    applied = rec.summaries["engine"].extra["operator"]
    assert [(a["action"]["x"], a["action"]["y"]) for a in applied] == [(3.3, -2.2), (-3.3, 2.2)], applied
    for a in applied:  # the world frame of the logged tick shows the teleport
        assert (worlds[a["tick"]].ball_x, worlds[a["tick"]].ball_y) == (a["action"]["x"], a["action"]["y"])
    (forced,) = rec.summaries["referee"].extra["operator"]
    log = rec.summaries["referee"].extra["log"]
    assert {"tick": forced["tick"], "command": "CORNER", "team": "b", "cause": "operator"} in log


def test_a_bad_action_is_one_line_and_exit_2():
    bad = subprocess.run(
        [*ARENA, "operator", "--match", "x", "--connect", "tcp/127.0.0.1:1", '{"type": "teleport_bal"}'],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "ACTION 1:" in bad.stderr, bad.stderr


@pytest.mark.slow
def test_in_a_secure_match_only_the_operator_principal_gets_through(reap, tmp_path):
    import time

    import zenoh

    from arena.schemas.messages import Operator, TeleportBall, encode

    port, mcap, creds = free_port(), tmp_path / "sec.mcap", tmp_path / "creds"
    endpoint = f"tls/127.0.0.1:{port}"
    match = spawn(
        "match", "--home", "BS", "--away", "BS", "--realtime", "--half-time", "4", "--secure", "--listen", endpoint,
        "--credentials", str(creds), "--match", "opsec", "--record", str(mcap), "--json",
    )  # fmt: skip
    reap.append(match)
    wait_for(lambda: (creds / "operator.json5").exists() and listening(f"tcp/127.0.0.1:{port}"), 60, "the router")
    # robot b/1's credentials: a put on the operator key is dropped by the router's access control
    frag = json.loads((creds / "robot-b-1.json5").read_text())
    c = zenoh.Config.from_json5(json.dumps(frag))
    c.insert_json5("connect/endpoints", json.dumps([endpoint]))
    c.insert_json5("scouting/multicast/enabled", "false")
    spy = zenoh.open(c)
    forged = encode(Operator(seq=1, actions=[TeleportBall(x=-1.1, y=1.1, vx=0.0, vy=0.0)]))
    op = subprocess.run(
        [*ARENA, "operator", "--match", "opsec", "--connect", endpoint, "--credentials", str(creds / "operator.json5"),
         '{"type": "teleport_ball", "x": 3.3, "y": -2.2, "vx": 0, "vy": 0}'],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert op.returncode == 0, op.stderr
    for _ in range(20):
        spy.put("arena/opsec/operator", forged)
        time.sleep(0.05)
    spy.close()
    out, err = match.communicate(timeout=120)
    assert match.returncode == 0, err
    applied = load(str(mcap)).summaries["engine"].extra["operator"]
    assert [(a["action"]["x"], a["action"]["y"]) for a in applied] == [(3.3, -2.2)], applied
