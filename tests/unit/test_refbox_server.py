"""The bridge's TCP server on real loopback sockets, and the worldstate scoring, without a match."""

from __future__ import annotations

import json
import logging
import socket
import time

from arena.recording.analysis.worldstates import score_team
from arena.refbox.server import BridgeServer
from arena.runtime.config import RefboxParams, RefboxTeam
from arena.schemas.messages import RobotState, World, Worldstate

LOG = logging.getLogger("test.refbox")


def recv_until_closed(sock: socket.socket, timeout: float = 5.0) -> bytes:
    sock.settimeout(timeout)
    out = b""
    while True:
        data = sock.recv(4096)
        if not data:
            return out
        out += data


def read_for(sock: socket.socket, seconds: float) -> bytes:
    sock.settimeout(0.05)
    out, end = b"", time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            out += sock.recv(4096)
        except TimeoutError:
            pass
    return out


def test_unknown_team_gets_reset_and_is_disconnected():
    table = (RefboxTeam(address="10.9.9.*", name="far away", target="224.16.32.99", side="a"),)
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x", teams=table), LOG)
    try:
        with socket.create_connection(("127.0.0.1", server.port)) as c:
            got = recv_until_closed(c)
        assert json.loads(got.rstrip(b"\0")) == {"command": "RESET", "targetTeam": ""}
        assert server.counts["refused"] == 1 and server.sides() == 0
    finally:
        server.close(linger=0)


def test_table_side_protocol_target_and_a_third_connection_refused():
    table = (RefboxTeam(address="127.0.0.*", name="local", target="224.16.32.127", side="b", protocol="legacy"),)
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x", teams=table), LOG)
    try:
        b = socket.create_connection(("127.0.0.1", server.port))
        assert read_for(b, 0.3) == b"W"
        with socket.create_connection(("127.0.0.1", server.port)) as again:  # side b is taken
            assert b"RESET" in recv_until_closed(again)
        server.broadcast("KICKOFF", "b")
        server.broadcast("START", "b")
        server.broadcast("IS_ALIVE", "b", 2)  # no legacy character: skipped
        assert read_for(b, 0.3) == b"ks"
        assert server.counts["not-in-legacy-protocol"] == 1
    finally:
        server.close(linger=0)
        b.close()


def test_no_table_first_is_a_second_is_b_swap_and_worldstates():
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x", swap=True, protocol_b="legacy"), LOG)
    try:
        a = socket.create_connection(("127.0.0.1", server.port))
        assert json.loads(read_for(a, 0.3).rstrip(b"\0")) == {"command": "WELCOME", "targetTeam": "224.16.32.202"}
        b = socket.create_connection(("127.0.0.1", server.port))
        assert read_for(b, 0.3) == b"W"
        server.broadcast("CORNER", "a")  # a is magenta when swapped
        assert read_for(b, 0.3) == b"c"
        assert b'"targetTeam":"224.16.32.202"' in read_for(a, 0.1)
        a.sendall(b'{"type":"worldstate"}\0{oops\0')
        time.sleep(0.3)
        results = server.drain()
        assert [(t, r.reason) for t, _, r, _ in results] == [("a", "missing-key"), ("a", "malformed-json")]
        assert dict(server.errors["a"]) == {"missing-key": 1, "malformed-json": 1}
    finally:
        server.close(linger=0)
        a.close()
        b.close()


def ws(tick: int, doc: dict) -> Worldstate:
    return Worldstate(tick=tick, team="a", age_ms=float(doc["ageMs"]), json=json.dumps(doc))


def test_scoring_against_ground_truth():
    worlds = [
        World(
            tick=k,
            t=k * 0.02,
            ball_x=1.0 + k,
            ball_y=0.0,
            robots=[
                RobotState(team="a", robot=0, x=0.0, y=0.0, theta=3.0),
                RobotState(team="b", robot=0, x=2.0, y=2.0, theta=0.0),
                RobotState(team="b", robot=1, x=-2.0, y=-2.0, theta=0.0),
            ],
        )
        for k in range(10)
    ]
    doc = {
        "type": "worldstate",
        "teamName": "t",
        "intention": "",
        "ageMs": 40,  # 2 ticks old: describes tick 3 when it came at tick 5
        "robots": [{"id": 0, "pose": [0.3, 0.4, -3.0]}, {"id": 7, "pose": [0, 0, 0]}],
        "balls": [{"position": [0.0, 0.0, 0.0], "confidence": 0.1}, {"position": [4.0, 0.0, 0.0], "confidence": 0.9}],
        "obstacles": [{"position": [2.2, 2.0]}, {"position": [5.0, 5.0]}],
    }
    s = score_team("a", [ws(5, doc)], worlds, dt=0.02)
    assert s["robots"]["0"]["position_m"]["mean"] == 0.5
    assert abs(s["robots"]["0"]["heading_rad"]["mean"] - (2 * 3.141592653589793 - 6.0)) < 1e-3
    assert s["unmatched_robots"] == 1
    assert s["ball_m"]["mean"] == 0.0  # the confident ball, at tick 3's true ball x = 4
    assert s["obstacles"] == {"recall": 0.5, "precision": 0.5, "opponents": 2, "reported": 2, "radius_m": 0.5}
    assert s["age_ms"]["mean"] == 40.0
