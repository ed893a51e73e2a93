"""--refbox-follow: a fake MSL RefBox (a TCP server written from the protocol description,
importing nothing of ours) plays a scripted game; our referee mirrors it into the match."""

from __future__ import annotations

import json
import socket
import subprocess
import threading
import time

import msgpack
from mcap.reader import make_reader

from tests.integration.helpers import ARENA, arena_json, free_port

CYAN, MAGENTA = "224.16.32.201", "224.16.32.202"  # the targets `arena match` expects by default
SCRIPT = [
    ("FIRST_HALF", ""),
    ("KICKOFF", CYAN),
    ("START", ""),
    ("STOP", ""),
    ("FREEKICK", MAGENTA),
    ("START", ""),
    ("TESTMODE_ON", ""),  # not a command of our referee: ignored and counted
    ("STOP", ""),
    ("CORNER", CYAN),
    ("START", ""),
    ("GOAL", CYAN),
    ("STOP", ""),
    ("KICKOFF", MAGENTA),
    ("START", ""),
]


class FakeRefBox(threading.Thread):
    def __init__(self):
        super().__init__(daemon=True)
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.peer = ""

    def run(self) -> None:
        """Every connection gets the script (`arena match` first connects once to check that one answers)."""
        self.server.settimeout(120)
        with self.server:
            while True:
                try:
                    conn, addr = self.server.accept()
                except OSError:
                    return
                self.peer = addr[0]
                threading.Thread(target=self.play, args=(conn,), daemon=True).start()

    def play(self, conn: socket.socket) -> None:
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        with conn:
            try:
                conn.sendall(json.dumps({"command": "WELCOME", "targetTeam": CYAN}).encode() + b"\0")
                for command, target in SCRIPT:  # 0.7 s in all: well inside the match's 2 s
                    time.sleep(0.05)
                    conn.sendall(json.dumps({"command": command, "targetTeam": target}).encode() + b"\0")
            except OSError:
                return  # the check's connection, closed at once
            time.sleep(30)  # stay connected while the match plays


def test_refbox_follow_plays_the_scripted_commands(tmp_path):
    refbox = FakeRefBox()
    refbox.start()
    path = tmp_path / "follow.mcap"
    result = arena_json(
        *("match", "--home", "BS", "--away", "BS", "--realtime", "--half-time", "1", "--seed", "5"),
        *("--refbox-follow", f"127.0.0.1:{refbox.port}", "--record", str(path)),
    )
    assert refbox.peer == "127.0.0.1"
    assert result["score"] == [1, 0]
    follow = result["refbox_follow"]
    assert follow["endpoint"] == f"127.0.0.1:{refbox.port}" and follow["connected"] and follow["applied"] > 0
    assert result["events"] == {
        "FIRST_HALF": 1,
        "KICKOFF": 2,
        "START": 4,
        "STOP": 3,
        "FREEKICK": 1,
        "CORNER": 1,
        "GOAL": 1,
        "END_GAME": 1,  # the match's own clock still ends it
    }
    with open(path, "rb") as f:
        refs = [msgpack.unpackb(m.data) for _, ch, m in make_reader(f).iter_messages() if ch.topic == "referee"]
    played = [(c["name"], c["team"]) for r in refs for c in r["commands"]]
    expected = [(c, {CYAN: "a", MAGENTA: "b"}.get(t, "")) for c, t in SCRIPT if c != "TESTMODE_ON"]
    # START carries the team of the set piece it starts, as our own referee's does
    for i, (c, _) in enumerate(expected):
        if c == "START":
            expected[i] = ("START", expected[i - 1][1] if expected[i - 1][0] != "STOP" else "")
    assert played[: len(expected)] == expected
    corner = next(c for r in refs for c in r["commands"] if c["name"] == "CORNER")
    assert (abs(corner["x"]), abs(corner["y"])) == (5.75, 3.75)  # team a attacks +x in the first half


def test_an_unreachable_refbox_is_said_before_the_match_plays_and_voids_it():
    """It was silent while the match played, said `never connected` only in the report, and exited 0."""
    port = free_port()
    match = subprocess.Popen(
        [*ARENA, "match", "--home", "BS", "--away", "BS", "--realtime", "--half-time", "0.5", "--seed", "5",
         "--refbox-follow", f"127.0.0.1:{port}", "--json"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        first = match.stderr.readline()
        assert match.poll() is None, "said while the match plays, not after it"
        assert f"--refbox-follow 127.0.0.1:{port}: cannot connect (Connection refused)" in first, first
        out, err = match.communicate(timeout=120)
    finally:
        match.kill()
    assert match.returncode == 1, err
    assert json.loads(out)["outcome"] == "void"
    assert f"void: --refbox-follow 127.0.0.1:{port}: never connected" in err and "Traceback" not in err
