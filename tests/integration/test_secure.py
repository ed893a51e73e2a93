"""Secure matches against zenoh's real usrpwd, access control and TLS, and forged owned messages.

Both matches play the configuration of `baseline` (2 x 10 s, BS v BS, seed 4),
so whatever an attacker did, the digest must be the baseline's.
"""

from __future__ import annotations

import json
import os
import stat
import subprocess
import time

import msgspec
import pytest
import zenoh
from mcap.reader import make_reader

from arena.schemas.messages import BallEvent, Cmd, EngineEvents, Referee, Summary, TapBatch, TapFrame, encode
from tests.integration.helpers import ARENA, free_port, spawn, wait_for

GAME = ("--home", "BS", "--away", "BS", "--half-time", "10", "--seed", "4")


@pytest.fixture(scope="module")
def baseline() -> dict:
    """`arena match GAME --json`, unattacked, played by the in-process engine: the digests, score, events
    and message counts of the distributed one (tests/integration/test_engines.py), no processes started."""
    from arena import cli
    from arena.commands._live import full_config
    from arena.match import inprocess

    cfg, _ = full_config(cli.parser("match").parse_args(["match", *GAME]))
    return json.loads(json.dumps(inprocess.play_match(cfg).to_dict()))


def _client(fragment: dict | None, endpoint: str) -> zenoh.Config:
    c = zenoh.Config.from_json5(json.dumps(fragment)) if fragment else zenoh.Config()
    c.insert_json5("mode", '"client"')
    c.insert_json5("scouting/multicast/enabled", "false")
    c.insert_json5("connect/endpoints", json.dumps([endpoint]))
    return c


def _refused(fragment: dict | None, endpoint: str) -> bool:
    try:
        zenoh.open(_client(fragment, endpoint)).close()
    except zenoh.ZError:
        return True
    return False


def test_a_secure_match_keeps_team_b_out_of_team_a_and_a_hand_started_robot_plays(tmp_path, reap, baseline):
    port = free_port()
    creds = tmp_path / "creds"
    match = spawn(
        "match", *GAME, "--secure", "--listen", f"tcp/127.0.0.1:{port}", "--credentials", str(creds),
        "--external", "a/1", "--match", "sec", "--json",
    )  # fmt: skip
    reap.append(match)
    wait_for(lambda: "external" in match.stderr.readline(), 60, "the launcher's instructions")
    command = match.stderr.readline().split()
    assert command[:3] == ["arena", "run", "robot"] and "--credentials" in command
    assert command[command.index("--connect") + 1] == f"tls/127.0.0.1:{port}"
    for name in ("robot-b-1", "basestation-a", "referee", "viewer", "engine", "operator"):
        path = creds / f"{name}.json5"
        assert stat.S_IMODE(path.stat().st_mode) == 0o600, name
    frag = {p.stem: json.loads(p.read_text()) for p in creds.glob("*.json5")}
    assert frag["robot-b-1"]["transport"]["auth"]["usrpwd"]["user"] == "robot-b-1"
    endpoint = f"tls/127.0.0.1:{port}"

    # No credentials (TLS with the right CA, no user), or a wrong password: refused at connect.
    tls_only = {"transport": {"link": frag["viewer"]["transport"]["link"]}}
    assert _refused(tls_only, endpoint)
    wrong = json.loads(json.dumps(frag["robot-b-1"]))
    wrong["transport"]["auth"]["usrpwd"]["password"] = "guess"
    assert _refused(wrong, endpoint)

    # Team b's robot: may read its own order, never team a's order nor the world.
    heard = {"a-order": 0, "world": 0, "b-order": 0}
    spy = zenoh.open(_client(frag["robot-b-1"], endpoint))
    subs = [
        spy.declare_subscriber(
            "arena/sec/team/a/order/1", lambda s: heard.__setitem__("a-order", heard["a-order"] + 1)
        ),
        spy.declare_subscriber("arena/sec/world", lambda s: heard.__setitem__("world", heard["world"] + 1)),
        spy.declare_subscriber(
            "arena/sec/team/b/order/1", lambda s: heard.__setitem__("b-order", heard["b-order"] + 1)
        ),
    ]
    robot = subprocess.Popen([*ARENA, *command[1:]], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    reap.append(robot)
    wait_for(lambda: heard["b-order"] > 0, 90, "team b's own orders (the match playing)")
    # ... and may not put on team a's cmd or on the referee: every tick of the match, forged.
    cmd = spy.declare_publisher("arena/sec/robot/a/1/cmd")
    ref = spy.declare_publisher("arena/sec/referee")
    for t in range(0, 1001):
        cmd.put(encode(Cmd(tick=t, vx=-5.0, omega=3.0)))
        if t % 5 == 0:
            ref.put(encode(Referee(tick=t, stage="FIRST_HALF", command="STOP")))
    out, err = match.communicate(timeout=240)
    for s in subs:
        s.undeclare()
    spy.close()
    assert match.returncode == 0, err
    assert robot.wait(timeout=30) == 0, robot.stderr.read()
    result = json.loads(out)
    assert result["secure"] is True
    assert heard["a-order"] == 0 and heard["world"] == 0, heard
    assert result["digest"] == baseline["digest"], "a forged cmd or referee frame got through"
    assert result["rejected"] == 0 and result["conflicts"] in ({}, []), (
        result["rejected_reasons"],
        result["conflicts"],
    )
    a1 = next(p for p in result["processes"] if (p["kind"], p["team"], p["robot"]) == ("robot", "a", 1))
    assert a1["external"] and a1["pid"] == robot.pid
    assert result["distance_m"]["a/1"] > 0.5


def test_forged_summaries_events_and_taps_change_nothing(tmp_path, reap, baseline):
    """No --secure: anybody may put anything on the router; the owners' MACs keep results honest."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    mcap = tmp_path / "m.mcap"
    match = spawn(
        "match", *GAME, "--listen", endpoint, "--match", "forge", "--record", str(mcap), "--json",
        "--logs", str(tmp_path / "logs"),
    )  # fmt: skip
    reap.append(match)
    wait_for(lambda: os.path.exists(endpoint.split("/", 1)[1]), 30, "the router socket")
    everyone = ["engine", "referee", "basestation/a", "basestation/b"] + [
        f"robot/{t}/{n}" for t in "ab" for n in range(3)
    ]
    with zenoh.open(_client(None, endpoint)) as s:
        referee = s.declare_subscriber("arena/forge/referee", zenoh.handlers.FifoChannel(1000))
        first = wait_for(lambda: referee.try_recv(), 90, "the match to start")
        tick = msgspec.msgpack.decode(first.payload.to_bytes(), type=Referee).tick
        liar = Summary(
            tick=1000, process="referee", pid=1, digest="0" * 32, sent=0, rejected=0, extra={"score": [7, 0]}
        )
        dead = Summary(tick=5, process="engine", pid=1, digest="0" * 32, sent=0, rejected=0, dead=everyone)
        world = encode(Referee(tick=tick, stage="FIRST_HALF", command="START"))  # any msgpack: not a World
        rounds = 0
        while match.poll() is None and rounds < 400:
            while (sample := referee.try_recv()) is not None:
                tick = msgspec.msgpack.decode(sample.payload.to_bytes(), type=Referee).tick
            s.put("arena/forge/summary/referee", encode(liar))
            s.put("arena/forge/summary/engine", encode(dead))
            for t in range(tick, tick + 10):
                goal = EngineEvents(tick=t, events=[BallEvent(kind="GOAL", tick=t, team="a")])
                s.put("arena/forge/engine/events", encode(goal))
            frames = [TapFrame(key="world", tick=tick + 1, payload=world)]
            s.put(
                "arena/forge/tap/engine", encode(TapBatch(tick=tick + 1, process="engine", seq=rounds, frames=frames))
            )
            s.put("arena/forge/tap/robot/a/1", encode(TapBatch(tick=tick, process="robot/a/1", seq=0, frames=frames)))
            s.put("arena/forge/world", world)
            rounds += 1
            time.sleep(0.02)
        referee.undeclare()
    out, err = match.communicate(timeout=240)
    assert match.returncode == 0, err
    r = json.loads(out)
    assert rounds >= 10, f"only {rounds} rounds of forgeries before the match ended"
    assert r["score"] == baseline["score"] and r["events"] == baseline["events"]
    assert r["digest"] == baseline["digest"] and r["ticks"] == baseline["ticks"] and r["dead"] == []
    assert r["forged_summaries"]["summary/referee"] >= 1 and r["forged_summaries"]["summary/engine"] >= 1
    assert r["rejected_reasons"]["forged"] >= 3 * rounds, r["rejected_reasons"]
    assert "forged" in (tmp_path / "logs" / "referee.log").read_text()
    assert "forged summary/referee" in err
    assert r["recording"]["complete"] is True
    with open(mcap, "rb") as f:
        summary = make_reader(f).get_summary()
    counts = {summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()}
    assert counts["world"] == r["sent_by_key"]["world"] == baseline["sent_by_key"]["world"]
    assert counts["engine/events"] == baseline["sent_by_key"]["engine/events"]
