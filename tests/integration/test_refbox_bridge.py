"""Real base stations join a real-time match through the RefBox bridge (docs/refbox.md).

The clients here are written from the MSL RefBox protocol description only
(NUL-terminated JSON commands, or one character per command in the legacy
protocol; worldstates as NUL-terminated JSON back on the same socket). This
module imports nothing of the bridge: it sees the match through `arena match`,
TCP, the MCAP file and `arena review`, as a team would.
"""

from __future__ import annotations

import json
import select
import socket
import subprocess
import threading
import time
from subprocess import PIPE

from mcap.reader import make_reader

from tests.integration.helpers import ARENA, arena_json, free_port

# From the protocol description: legacy characters (upper case cyan, lower case magenta).
LEGACY = {"START": "s", "STOP": "S", "WELCOME": "W", "FIRST_HALF": "1", "SECOND_HALF": "2", "HALF_TIME": "h"}
LEGACY |= {"END_GAME": "e", "DROP_BALL": "N", "PARK": "L", "GAMEOVER": "z"}
LEGACY_TEAM = {"KICKOFF": "K", "FREEKICK": "F", "GOALKICK": "G", "THROWIN": "T", "CORNER": "C", "GOAL": "A"}
LEGACY_TEAM |= {"PENALTY": "P", "YELLOW_CARD": "Y", "RED_CARD": "R", "DOUBLE_YELLOW": "B", "REPAIR": "O"}
CYAN, MAGENTA = "224.16.32.201", "224.16.32.202"  # the bridge's documented default targetTeam strings


def connect(port: int, timeout: float = 90.0) -> socket.socket:
    deadline = time.monotonic() + timeout
    while True:
        try:
            return socket.create_connection(("127.0.0.1", port), timeout=2)
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)


def worldstate(n: int) -> bytes:
    doc = {
        "type": "worldstate",
        "teamName": "test client",
        "intention": "attack",
        "ageMs": 20 + n % 3,
        "robots": [
            {
                "id": i,
                "pose": [-1.0 * i, 0.5, 0.0],
                "targetPose": [0, 0, 0],
                "velocity": [0, 0, 0],
                "intention": "",
                "batteryLevel": 90.0,
                "ballEngaged": 0,
            }
            for i in range(3)
        ],  # fmt: skip
        "balls": [{"position": [0.0, 0.0, 0.11], "velocity": [0, 0, 0], "confidence": 0.8}],
        "obstacles": [{"position": [3.0, 0.0], "velocity": [0, 0], "radius": 0.25, "confidence": 0.5}],
    }
    return json.dumps(doc).encode() + b"\0"


class JsonBaseStation(threading.Thread):
    """Reads NUL-terminated JSON commands; sends worldstates at 10 Hz until END_GAME: good, malformed,
    missing a key, and once a message with no terminator for more than 100 kB."""

    def __init__(self, sock: socket.socket):
        super().__init__(daemon=True)
        self.sock = sock
        self.commands: list[tuple[str, str]] = []
        self.sent = {"good": 0, "malformed-json": 0, "missing-key": 0, "not-terminated": 0}

    def run(self) -> None:
        buf, n, next_send, sending = b"", 0, time.monotonic(), True
        self.sock.setblocking(False)
        while True:
            timeout = max(0.0, next_send - time.monotonic()) if sending else 1.0
            readable, _, _ = select.select([self.sock], [], [], timeout)
            if readable:
                data = self.sock.recv(4096)
                if not data:
                    break
                buf += data
                while b"\0" in buf:
                    raw, buf = buf.split(b"\0", 1)
                    msg = json.loads(raw)
                    self.commands.append((msg["command"], msg["targetTeam"]))
                    if msg["command"] == "END_GAME":
                        sending = False
            if sending and time.monotonic() >= next_send:
                next_send += 0.1
                n += 1
                if n == 3:
                    self.sock.setblocking(True)
                    self.sock.sendall(b"x" * 100_500 + b"\0")
                    self.sock.setblocking(False)
                    self.sent["not-terminated"] += 1
                elif n % 10 == 4:
                    self.sock.sendall(b'{"type": "worldstate", "ageMs": 3,\0')
                    self.sent["malformed-json"] += 1
                elif n % 10 == 7:
                    self.sock.sendall(b'{"type": "worldstate", "ageMs": 3, "teamName": "t", "intention": ""}\0')
                    self.sent["missing-key"] += 1
                else:
                    self.sock.sendall(worldstate(n))
                    self.sent["good"] += 1
        self.sock.close()


class LegacyBaseStation(threading.Thread):
    def __init__(self, sock: socket.socket):
        super().__init__(daemon=True)
        self.sock = sock
        self.chars = ""

    def run(self) -> None:
        self.sock.settimeout(120)
        while data := self.sock.recv(4096):
            self.chars += data.decode("ascii")
        self.sock.close()


def in_order(seq: list, wanted: list) -> bool:
    it = iter(seq)
    return all(any(x == w for x in it) for w in wanted)


def test_two_base_stations_in_a_realtime_match(tmp_path):
    port = free_port()
    mcap_path = tmp_path / "match.mcap"
    args = ["match", "--home", "BS", "--away", "BS", "--realtime", "--half-time", "2", "--seed", "4"]
    args += ["--refbox", f"tcp/127.0.0.1:{port}", "--refbox-protocol", "b=legacy", "--refbox-wait", "2"]
    args += ["--record", str(mcap_path), "--json"]
    match = subprocess.Popen([*ARENA, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        cyan = JsonBaseStation(connect(port))  # the first connection is team a, cyan
        cyan.start()
        deadline = time.monotonic() + 30
        while not cyan.commands and time.monotonic() < deadline:
            time.sleep(0.02)
        magenta = LegacyBaseStation(connect(port))
        magenta.start()
        out, err = match.communicate(timeout=180)
    finally:
        if match.poll() is None:
            match.kill()
            match.communicate()
    assert match.returncode == 0, err[-3000:]
    cyan.join(10)
    magenta.join(10)
    result = json.loads(out)

    names = [c for c, _ in cyan.commands]
    assert cyan.commands[:4] == [("WELCOME", CYAN), ("FIRST_HALF", ""), ("KICKOFF", CYAN), ("START", "")]
    assert in_order(cyan.commands, [("HALF_TIME", ""), ("SECOND_HALF", ""), ("KICKOFF", MAGENTA), ("START", "")])
    assert names[-3:] == ["END_GAME", "PARK", "GAMEOVER"]
    # The legacy client got the very same commands, one character each.
    expected = "".join(
        LEGACY[c] if c in LEGACY else (LEGACY_TEAM[c] if t == CYAN else LEGACY_TEAM[c].lower())
        for c, t in cyan.commands
    )
    assert magenta.chars == expected
    assert magenta.chars.startswith("W1Ks") and "h2ks" in magenta.chars and magenta.chars.endswith("eLz")

    # Every bad worldstate counted with its reason; the match went on to the end.
    bad = {k: v for k, v in cyan.sent.items() if k != "good" and v}
    assert result["refbox"]["worldstate_errors"]["a"] == bad
    for reason, n in bad.items():
        assert result["rejected_reasons"][f"worldstate-{reason}"] == n
    # 4 s of play at 10 Hz: about 40 sent, 30 of them good (the bad ones come at n = 3, 4, 7, 14, 17, ...)
    assert cyan.sent["good"] >= 20 and result["ticks"] == 200

    # The good ones are in the MCAP, on team a's channel.
    with open(mcap_path, "rb") as f:
        topics = [ch.topic for _, ch, _ in make_reader(f).iter_messages()]
    assert topics.count("refbox/a/worldstate") == cyan.sent["good"]
    assert topics.count("refbox/b/worldstate") == 0

    # The table and the JSON: two `arena review` processes at once.
    reviews = [
        subprocess.Popen([*ARENA, "review", str(mcap_path), *flag], stdout=PIPE, stderr=PIPE, text=True)
        for flag in ((), ("--json",))
    ]
    (table, table_err), (as_json, json_err) = (r.communicate(timeout=120) for r in reviews)
    assert [r.returncode for r in reviews] == [0, 0], table_err + json_err
    assert "worldstate accuracy, team a" in table and "team b (" not in table
    for row in ("robot 0 position", "robot 2 heading", "ball position", "ageMs", "recall", "precision"):
        assert row in table, row
    scored = json.loads(as_json)["worldstate_accuracy"]["a"]
    assert scored["worldstates"] == cyan.sent["good"] and scored["age_ms"]["max"] <= 22


def test_lockstep_bridge_changes_no_digest():
    """In lockstep the bridge only listens: with it (and no base station), the same digests as without."""
    base = ["match", "--home", "AD", "--away", "BS", "--half-time", "2", "--seed", "9"]
    plain = arena_json(*base)
    bridged = arena_json(*base, "--refbox", f"tcp/127.0.0.1:{free_port()}")
    assert bridged["digest"] == plain["digest"]
    assert bridged["process_digests"] == plain["process_digests"]
    assert bridged["refbox"]["commands_forwarded"] == sum(plain["events"].values())


def test_via_refbox_our_base_stations_through_the_bridge(tmp_path):
    """--via-refbox: both of our base stations take their commands over TCP from the bridge and
    send their world model back as worldstates, which review scores against the ground truth."""
    path = tmp_path / "via.mcap"
    result = arena_json(
        *("match", "--home", "BS", "--away", "AD", "--realtime", "--half-time", "3", "--seed", "2"),
        *("--refbox", f"tcp/127.0.0.1:{free_port()}", "--via-refbox", "--record", str(path)),
    )
    counts = result["refbox"]["counts"]
    assert counts["connections"] == 2 and "refused" not in counts
    # WELCOME and every command from the first on; the last tick's END_GAME, PARK and GAMEOVER
    # may find a base station already gone.
    for team in ("a", "b"):
        assert 0 <= result["refbox"]["commands_forwarded"] + 1 - counts[f"commands_to_{team}"] <= 3
    assert counts["worldstates_a"] > 20 and counts["worldstates_b"] > 20
    review = json.loads(
        subprocess.run([*ARENA, "review", str(path), "--json"], capture_output=True, text=True, timeout=120).stdout
    )["worldstate_accuracy"]
    for team in ("a", "b"):
        assert review[team]["worldstates"] == counts[f"worldstates_{team}"]
        for robot in review[team]["robots"].values():
            assert robot["position_m"]["mean"] < 0.3  # their own localisation, a few cm of sensor noise and lag


def test_via_refbox_is_refused_in_lockstep():
    r = subprocess.run(
        [*ARENA, "match", "--home", "BS", "--away", "BS", "--refbox", "tcp/127.0.0.1:0", "--via-refbox"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 2 and "--via-refbox needs --realtime" in r.stderr and "Traceback" not in r.stderr


class CommandCollector(threading.Thread):
    """A good base station: reads NUL-terminated JSON commands until the bridge closes."""

    def __init__(self, sock: socket.socket):
        super().__init__(daemon=True)
        self.sock = sock
        self.commands: list[tuple[str, str]] = []

    def run(self) -> None:
        self.sock.settimeout(120)
        buf = b""
        while data := self.sock.recv(4096):
            buf += data
            *messages, buf = buf.split(b"\0")
            self.commands += [(m["command"], m["targetTeam"]) for m in map(json.loads, messages)]
        self.sock.close()


def test_a_100_kB_message_at_the_start_changes_nothing():
    """`"` and 49,990 escaped quotes, sent by the first base station as soon as it is welcomed, in
    a real-time match: the match starts and ends on time, the other base station gets every
    command, and the message is counted as one malformed worldstate."""
    port = free_port()
    args = ["match", "--home", "AD", "--away", "BS", "--realtime", "--half-time", "2", "--seed", "9"]
    match = subprocess.Popen(
        [*ARENA, *args, "--refbox", f"tcp/127.0.0.1:{port}", "--refbox-wait", "2", "--json"],
        stdout=PIPE,
        stderr=PIPE,
        text=True,
    )
    try:
        hostile = connect(port)
        hostile.recv(4096)  # WELCOME
        hostile.sendall(b'"' + b'\\"' * 49_990 + b"\0")
        good = CommandCollector(connect(port))
        good.start()
        out, err = match.communicate(timeout=180)
    finally:
        if match.poll() is None:
            match.kill()
            match.communicate()
    assert match.returncode == 0, err[-3000:]
    good.join(10)
    hostile.close()
    result = json.loads(out)
    assert result["ticks"] == 200 and "void" not in json.dumps(result.get("status", ""))
    assert result["refbox"]["worldstate_errors"] == {"a": {"malformed-json": 1}, "b": {}}
    # WELCOME, then every command of the match, the last tick's GAMEOVER included.
    counts = result["refbox"]["counts"]
    assert len(good.commands) == result["refbox"]["commands_forwarded"] + 1 == counts["commands_to_b"]
    assert good.commands[0][0] == "WELCOME" and good.commands[-1][0] == "GAMEOVER"
