"""The bridge's TCP server on real loopback sockets, and the worldstate scoring, without a match."""

from __future__ import annotations

import json
import logging
import socket
import time

from arena.config import RefboxParams, RefboxTeam
from arena.recording.analysis.worldstates import score_team
from arena.refbox.server import MAX_BURST, MAX_RATE, BridgeServer, Client
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


def read_through(sock: socket.socket, end: bytes, timeout: float = 5.0) -> bytes:
    """All `sock` receives up to `end`, which the test had the server send last: the server sends in the
    order it was told to, so nothing it sent before `end` can still be on its way (a byte too many fails
    the comparison, or never ends with `end`)."""
    sock.settimeout(timeout)
    out = b""
    while not out.endswith(end):
        data = sock.recv(4096)
        if not data:
            return out
        out += data
    return out


STOP = b'{"command":"STOP","targetTeam":""}\0'  # the last command a test sends, to know the rest has come


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
        assert read_through(b, b"W") == b"W"
        with socket.create_connection(("127.0.0.1", server.port)) as again:  # side b is taken
            assert b"RESET" in recv_until_closed(again)
        server.broadcast("KICKOFF", "b")
        server.broadcast("START", "b")
        server.broadcast("IS_ALIVE", "b", 2)  # no legacy character: skipped
        server.broadcast("STOP")
        assert read_through(b, b"S") == b"ksS"  # nothing for IS_ALIVE
        assert server.counts["not-in-legacy-protocol"] == 1
    finally:
        b.close()  # first: the server's close waits (0.5 s) for a base station that does not hang up
        server.close(linger=0)


def test_no_table_first_is_a_second_is_b_swap_and_worldstates():
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x", swap=True, protocol_b="legacy"), LOG)
    try:
        a = socket.create_connection(("127.0.0.1", server.port))
        assert json.loads(read_through(a, b"\0").rstrip(b"\0")) == {"command": "WELCOME", "targetTeam": "224.16.32.202"}
        b = socket.create_connection(("127.0.0.1", server.port))
        assert read_through(b, b"W") == b"W"
        server.broadcast("CORNER", "a")  # a is magenta when swapped
        server.broadcast("STOP")
        assert read_through(b, b"S") == b"cS"
        corner, stop, rest = read_through(a, STOP).split(b"\0")
        assert b'"targetTeam":"224.16.32.202"' in corner and stop + b"\0" == STOP and rest == b""
        a.sendall(b'{"type":"worldstate"}\0{oops\0')
        results: list = []
        deadline = time.monotonic() + 5.0
        while len(results) < 2 and time.monotonic() < deadline:  # both messages read
            results += server.drain()
            time.sleep(0.005)
        assert [(t, r.reason) for t, _, r, _ in results] == [("a", "missing-key"), ("a", "malformed-json")]
        assert dict(server.errors["a"]) == {"missing-key": 1, "malformed-json": 1}
    finally:
        a.close()  # first: the server's close waits (0.5 s) for a base station that does not hang up
        b.close()
        server.close(linger=0)


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


def connect_as_a(server: BridgeServer) -> socket.socket:
    """A fresh connection that gets side a (the previous one is gone): WELCOME read."""
    deadline = time.monotonic() + 5.0
    while server.sides() and time.monotonic() < deadline:
        time.sleep(0.005)
    sock = socket.create_connection(("127.0.0.1", server.port))
    sock.settimeout(5.0)
    got = b""
    while b"\0" not in got:
        got += sock.recv(4096) or b"\0"
    assert b"WELCOME" in got, got
    return sock


GOOD = json.dumps({"type": "worldstate", "ageMs": 5, "teamName": "T", "intention": "", "robots": [],
                   "balls": [], "obstacles": []}).encode() + b"\0"  # fmt: skip


def still_serves(server: BridgeServer) -> None:
    """The server thread lives, takes a new base station, and counts its good worldstate."""
    assert server.thread.is_alive()
    before = server.counts["worldstates_a"]
    sock = connect_as_a(server)
    try:
        sock.sendall(GOOD)
        deadline = time.monotonic() + 5.0
        while server.counts["worldstates_a"] == before and time.monotonic() < deadline:
            time.sleep(0.005)
        assert server.counts["worldstates_a"] == before + 1
    finally:
        sock.close()


def test_2000_brackets_are_refused_unparsed_and_their_sender_disconnected():
    """Issue 36: `[` * 2000 raised RecursionError in the JSON parser, which killed the server
    thread; the bridge then exited 2 on its next send ("Bad file descriptor")."""
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x"), LOG)
    try:
        sock = connect_as_a(server)
        sock.sendall(b"[" * 2000 + b"\0")
        assert recv_until_closed(sock) == b"", "disconnected"
        sock.close()
        assert server.errors["a"]["too-deep"] == 1
        server.broadcast("START")  # the match goes on
        still_serves(server)
    finally:
        server.close(linger=0)


def test_the_bridge_survives_any_input_on_its_socket():
    """Hypothesis drives the real TCP socket: random bytes, deep nesting, long and unterminated
    messages, broken UTF-8 and almost-valid worldstates, in random cuts. After every example the
    server thread lives, counts every bad message by reason, and serves a new base station."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    nested = st.tuples(st.integers(1, 5000), st.sampled_from(["[", "{", '{"a":', "[{"])).map(
        lambda t: (t[1] * t[0]).encode()
    )
    almost = st.dictionaries(st.sampled_from(["type", "ageMs", "teamName", "robots", "x"]),
                             st.recursive(st.none() | st.floats() | st.text(max_size=4),
                                          lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=3), c, max_size=3),
                                          max_leaves=20)).map(lambda d: json.dumps(d).encode())  # fmt: skip
    message = st.one_of(st.binary(max_size=300), nested, almost, st.just(b"\xff\xfe\xc0"), st.just(GOOD[:-1]))
    stream = st.lists(st.tuples(message, st.booleans()), min_size=1, max_size=6).map(
        lambda ms: b"".join(m + (b"\0" if end else b"") for m, end in ms)
    )
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x"), LOG)

    @settings(max_examples=150, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(stream, st.integers(1, 4096))
    def feed(data: bytes, cut: int) -> None:
        sock = connect_as_a(server)
        try:
            for i in range(0, len(data), cut):
                sock.sendall(data[i : i + cut])
        except OSError:
            pass  # disconnected for misbehaving: allowed
        finally:
            sock.close()
        assert server.thread.is_alive()

    try:
        feed()
        assert sum(server.errors["a"].values()) > 0
        assert set(server.errors["a"]) <= {
            "malformed-json",
            "missing-key",
            "wrong-type",
            "not-terminated",
            "too-deep",
            "flooding",
        }
        still_serves(server)
    finally:
        server.close(linger=0)


def wait_for(cond, timeout: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout
    while not cond() and time.monotonic() < deadline:
        time.sleep(0.005)
    return cond()


def closed_by_peer(sock: socket.socket, timeout: float) -> bool:
    """Whether the other end closed `sock` having sent nothing more: the end of the stream, or a reset
    (a server that closes with our bytes unread resets the connection). Silence raises TimeoutError."""
    try:
        return recv_until_closed(sock, timeout) == b""
    except ConnectionResetError:
        return True


def test_a_hostile_base_station_neither_stalls_the_other_nor_stays():
    """Team a sends the 100 kB message of escaped quotes (a bad message, counted; its connection
    stays, as an honest station's typo would) and then floods; team b is served throughout, and the
    flooding connection is cut off.

    The budget's clock stands still: a connection may then send `MAX_BURST` bytes in all, and the
    flood is cut off after them whenever this host's scheduler lets the server read them. (With the
    wall clock and a 5 s send timeout, a server thread stalled for 5 s ended the flood early, and
    the cut-off's reset then came to a socket nobody sent on: ConnectionResetError.)
    `test_the_byte_budget_refills_at_max_rate` checks the rate itself."""
    server = BridgeServer("127.0.0.1", 0, RefboxParams(listen="x"), LOG, budget_clock=lambda: 0.0)
    try:
        hostile = connect_as_a(server)
        good = socket.create_connection(("127.0.0.1", server.port))
        assert b"WELCOME" in read_through(good, b"\0")
        hostile.sendall(b'"' + b'\\"' * 49_990 + b"\0" + GOOD)
        good.sendall(GOOD)
        assert wait_for(lambda: server.counts["worldstates_a"] == 1 and server.counts["worldstates_b"] == 1)
        assert server.errors["a"] == {"malformed-json": 1} and server.sides() == 2
        hostile.settimeout(60.0)  # a bound only: 5 s ended a send to a stalled server before the budget
        try:  # far past the budget: it is cut off while still sending
            for _ in range(4 * MAX_BURST >> 20):
                hostile.sendall(b"x" * (1 << 20))
        except OSError:
            pass
        assert closed_by_peer(hostile, timeout=10.0), "disconnected"
        assert server.errors["a"]["flooding"] == 1 and server.sides() == 1
        server.broadcast("STOP")
        good.sendall(GOOD)
        assert read_through(good, STOP) == STOP
        assert wait_for(lambda: server.counts["worldstates_b"] == 2)
        good.close()
        hostile.close()
    finally:
        server.close(linger=0)


def test_the_byte_budget_refills_at_max_rate():
    """A connection may send `MAX_BURST` at once and `MAX_RATE` a second on average for as long as it
    likes; a tenth more than that is flooding within a minute. Times are given, not measured."""
    client = Client(sock=None, address="127.0.0.1", side="a", protocol="json", since=0.0)  # type: ignore[arg-type]
    assert client.spend(MAX_BURST, 0.0) and not client.spend(1, 0.0)
    steady = Client(sock=None, address="127.0.0.1", side="a", protocol="json", since=0.0)  # type: ignore[arg-type]
    assert all(steady.spend(MAX_RATE // 10, t / 10) for t in range(1, 36_000))  # an hour at MAX_RATE
    flood = Client(sock=None, address="127.0.0.1", side="a", protocol="json", since=0.0)  # type: ignore[arg-type]
    cut = next(t for t in range(1, 36_000) if not flood.spend(MAX_RATE * 11 // 100, t / 10))
    assert cut / 10 < 60, cut
