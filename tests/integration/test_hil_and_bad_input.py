"""Hardware-in-the-loop (a robot started by hand), garbage on the wire, and `arena up compose.yaml`."""

from __future__ import annotations

import json
import os
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path

import msgspec
import zenoh

from arena.runtime.mac import tag
from arena.runtime.session import NetConfig, open_session
from arena.schemas.messages import RefCommand, Referee, Report, encode
from tests.integration.helpers import ARENA, spawn, wait_for

REPO = Path(__file__).resolve().parents[2]


def test_a_robot_started_by_hand_plays_its_part(tmp_path, reap):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    match = spawn(
        "match",
        "--home",
        "BS",
        "--away",
        "BS",
        "--half-time",
        "5",  # what it checks holds at every tick: 500 of them as well as 2000
        "--seed",
        "4",
        "--external",
        "a/1",
        "--match",
        "hil",
        "--listen",
        endpoint,
        "--json",
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
    # Its digest was recomputed from the frames it put (match/witness.py), not taken on trust.
    assert result["digests_verified"] == ["robot/a/1"]


@contextmanager
def _client_of_a_match(tmp_path, reap, match_id: str, seed: int, half_time: int):
    """Start a 2 x `half_time` s BS v BS match on a socket in `tmp_path`; yield (the match process, a client session)."""
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    match = spawn(
        "match",
        "--home",
        "BS",
        "--away",
        "BS",
        "--half-time",
        str(half_time),
        "--seed",
        str(seed),
        "--match",
        match_id,
        "--listen",
        endpoint,
        "--json",
        "--logs",
        str(tmp_path / "logs"),
        "--credentials",
        str(tmp_path / "creds"),
    )
    reap.append(match)
    wait_for(lambda: Path(endpoint.split("/", 1)[1]).exists(), 30, "the router socket")
    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        yield match, session


def _as(tmp_path, match_id: str, sender: str, key: str):
    """The MAC of `sender` on `key` (`sign(payload)`), from the match's credentials directory: an
    insider's frames reach every receiver's decoder and checks; a stranger's are dropped as forged."""
    frag = json.loads((tmp_path / "creds" / f"{sender.replace('/', '-')}.json5").read_text())
    own = bytes.fromhex(frag["metadata"]["arena"]["keys"][sender])
    return lambda payload: tag(own, f"arena/{match_id}/{key}", payload)


def _result(match) -> dict:
    out, err = match.communicate(timeout=240)
    assert match.returncode == 0, err
    return json.loads(out)


def _put_during_a_match(tmp_path, reap, match_id: str, seed: int, key: str, sender: str, payloads) -> dict:
    """Play a 2 x 5 s match; once it is under way, put `payloads(tick)` on `key` with `sender`'s MAC.
    Returns the match JSON.

    `tick` is the tick of the first referee frame heard: the match is at or past it.
    """
    with _client_of_a_match(tmp_path, reap, match_id, seed, half_time=5) as (match, session):
        # Wait until the match is being played: the referee has sent a frame. Stop
        # listening before publishing: on the referee key we would hear ourselves.
        referee = session.declare_subscriber(f"arena/{match_id}/referee", zenoh.handlers.FifoChannel(1000))
        first = wait_for(lambda: referee.try_recv(), 60, "the match to start")
        referee.undeclare()
        tick = msgspec.msgpack.decode(first.payload.to_bytes(), type=Referee).tick
        pub = session.declare_publisher(f"arena/{match_id}/{key}", congestion_control=zenoh.CongestionControl.BLOCK)
        sign = _as(tmp_path, match_id, sender, key)
        for payload in payloads(tick):
            pub.put(payload, attachment=sign(payload))
        return _result(match)


def test_garbage_on_a_robots_cmd_key_is_rejected_and_the_match_goes_on(tmp_path, reap):
    bad = [
        b"\xde\xad\xbe\xef",  # not msgpack
        b"",  # empty
        msgspec.msgpack.encode({"tick": "soon", "vx": 1.0}),  # wrong type
        msgspec.msgpack.encode([1, 2, 3]),  # not a map
        encode(Report(tick=0, robot=1, pose={"x": 0, "y": 0, "theta": 0})),  # another message type (no tick order)
        msgspec.msgpack.encode({"tick": 999_999, "vx": float("nan")}),  # out of sequence
    ]
    result = _put_during_a_match(tmp_path, reap, "noisy", 5, "robot/a/1/cmd", "robot/a/1", lambda tick: bad * 5)
    assert result["rejected"] >= len(bad) * 5 - 5, result["rejected_reasons"]
    assert result["rejected_reasons"].get("malformed", 0) >= 4 * 5
    log = (tmp_path / "logs" / "engine.log").read_text()
    assert "rejected input on arena/noisy/robot/a/1/cmd: malformed" in log
    assert "out-of-sequence" in log
    assert result["events"]["END_GAME"] == 1 and result["ticks"] == 500


def test_bad_referee_commands_are_rejected_by_engine_and_base_stations(tmp_path, reap):
    """Unknown command names and teams on the `referee` key: rejected, counted, logged; the match goes on.

    In lockstep a receiver accepts a referee frame only for the tick it waits
    for next, so a bad frame meets `check_referee` only if it arrives before
    the real referee's frame for that tick. The test keeps listening to the
    real referee and, every 20 ms, puts bad frames for the next two referee
    ticks, until the match ends; some of them win that race at every receiver.
    (A single burst sent once at the start lost it at times: the match may be
    far on by the time it arrives.)
    """
    decode = msgspec.msgpack.Decoder(Referee).decode
    rounds = 0
    with _client_of_a_match(tmp_path, reap, "refnoise", 6, half_time=10) as (match, session):
        referee = session.declare_subscriber("arena/refnoise/referee", zenoh.handlers.FifoChannel(1000))
        # REMOTE: our own subscriber above does not hear the bad frames.
        pub = session.declare_publisher(
            "arena/refnoise/referee",
            congestion_control=zenoh.CongestionControl.BLOCK,
            allowed_destination=zenoh.Locality.REMOTE,
        )
        sign = _as(tmp_path, "refnoise", "referee", "referee")
        wait_for(lambda: match.poll() is not None or referee.try_recv() is not None, 60, "the match to start")
        while match.poll() is None:
            heard = None
            while (sample := referee.try_recv()) is not None:
                heard = sample
            if heard is not None:
                tick = decode(heard.payload.to_bytes()).tick
                for t in (tick + 5, tick + 10):
                    for msg in (
                        Referee(tick=t, stage="FIRST_HALF", command="CELEBRATE"),  # not an MSL command: no decode
                        Referee(tick=t, stage="FIRST_HALF", command="START", commands=[RefCommand(name="CORNER")]),
                        Referee(tick=t, stage="FIRST_HALF", command="START", command_team="c"),  # no team c
                    ):  # fmt: skip
                        payload = encode(msg)
                        pub.put(payload, attachment=sign(payload))  # with the referee's key: reaches every check
                    pub.put(encode(Referee(tick=t, stage="FIRST_HALF", command="STOP")))  # no MAC: forged
                rounds += 1
            time.sleep(0.02)
        result = _result(match)
    assert rounds >= 10, f"only {rounds} rounds of bad frames before the match ended"
    reasons = result["rejected_reasons"]
    assert reasons.get("invalid", 0) >= 2, reasons  # at least one per base station
    # Team c and command CELEBRATE never decode (the wire types are Literal), whatever the tick;
    # the engine and both base stations read them.
    assert 2 <= reasons.get("malformed", 0) <= 3 * 4 * rounds, reasons
    logs = tmp_path / "logs"
    for process in ("basestation_a", "basestation_b"):
        log = (logs / f"{process}.log").read_text()
        assert "rejected input on arena/refnoise/referee: invalid:" in log, process
        assert "malformed: Invalid enum value 'c'" in log, process
        # Every receiver holds the referee's MAC key (runtime/mac.py): a frame without a valid MAC
        # never reaches its checks, whatever its content.
        assert "rejected input on arena/refnoise/referee: forged: not from referee" in log, process
    assert "rejected input on arena/refnoise/referee: forged: not from referee" in (logs / "engine.log").read_text()
    assert result["forged"]["referee"] >= 3 * rounds, result["forged"]
    assert result["events"]["END_GAME"] == 1 and result["ticks"] == 1000


def test_arena_up_runs_the_compose_file_as_local_processes():
    env = dict(os.environ, ARENA_HALF_TIME="3", ARENA_SEED="2")
    run = subprocess.run(
        [*ARENA, "up", str(REPO / "compose.yaml"), "--json"], capture_output=True, text=True, env=env, timeout=240
    )
    assert run.returncode == 0, run.stderr[-3000:]
    r = json.loads(run.stdout)
    # What it plays, and how to change it, is said before it plays (it was 2 x 300 s without a word).
    assert "2 x 3 s simulated, seed 2, link wifi" in run.stderr and "ARENA_HALF_TIME" in run.stderr
    assert r["services"][0] == "router" and len(r["services"]) == 11
    assert len({p["pid"] for p in r["processes"]}) == 10
    assert r["seed"] == 2 and r["half_time"] == 3.0 and r["link"] == "wifi"
    assert r["events"]["END_GAME"] == 1
    # The router service writes the credentials (`--credentials`): every service is a zenoh user of a
    # secure match, and `arena up` collects the summaries as the `collector` principal, MACs checked.
    assert r["secure"] and r["rejected_reasons"] == {} and r["forged_summaries"] == {}
