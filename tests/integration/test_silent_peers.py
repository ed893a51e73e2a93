"""Two measured cases of issues 15 and 20: a robot that never sends its `report`, and forged NaN orders.

Real processes over real zenoh. The silent robot is an external robot/a/1,
started with the command the launcher prints, through `arena.cli.main` with
one change: it never sends a `report`. The forged orders come from a plain
zenoh client, encoded with plain msgpack.
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading

import msgpack
import pytest
import zenoh

from arena.runtime.mac import tag
from tests.integration.helpers import spawn, wait_for

MATCH = ("match", "--home", "BS", "--away", "BS", "--json")


def finish(proc, timeout: float = 300) -> tuple[int, dict | None, str]:
    out, err = proc.communicate(timeout=timeout)
    return proc.returncode, (json.loads(out) if out.strip() else None), err


NO_REPORT = """
import sys
from arena.processes.robot import RobotNode
from arena.cli import main

# Plays every tick (its cmd, its Summary) but never sends a report: the report schedule is never due.
class Never:
    def due(self, k):
        return False

init = RobotNode.__init__
def patched(self, *args, **kwargs):
    init(self, *args, **kwargs)
    self.report_schedule = Never()
RobotNode.__init__ = patched
sys.exit(main(sys.argv[1:]))
"""


def play_with_a_silent_robot(reap, tmp_path, secure) -> dict:
    """Issue 20: it used to give ticks 0, the engine dead and exit 0 after every watchdog fired at once.

    Its base station waits for the report, everyone downstream waits for the base station. A short
    wait_timeout (2 s, from a --config file; 60 s by default) keeps the test short: the match stalls
    for about twice that. With it, every process announces its wait (after a quarter of it), so only
    the base station, whose sender owes the frame, gives up. With --secure, the
    router's access control lets each process declare its own waiting tokens and read everyone's.
    """
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    config = tmp_path / "quick.toml"
    config.write_text("[timing]\nwait_timeout = 2.0\n")
    proc = spawn(*MATCH, "--config", str(config), "--half-time", "10", "--seed", "4", "--match", "noreport",
                 "--listen", endpoint, "--external", "a/1", secure)  # fmt: skip
    reap.append(proc)
    line = ""
    while not line.strip().startswith("arena run robot"):
        line = wait_for(lambda: proc.stderr.readline(), 60, "the launcher's instructions")
    robot = subprocess.Popen([sys.executable, "-c", NO_REPORT, *line.split()[1:]],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
    reap.append(robot)
    code, result, err = finish(proc, 180)
    assert code == 0, err
    assert result["ticks"] == 1000 and result["events"]["END_GAME"] == 1, "it used to stall at tick 0"
    assert result["outcome"] == "completed_with_faults", result["outcome_reasons"]
    assert result["sent_by_key"]["team/a/report/1"] == 0 and result["sent_by_key"]["robot/a/1/cmd"] == 1001
    assert "fault: robot/a/1" in err and "Traceback" not in err
    return result


@pytest.mark.parametrize("secure", ["--no-secure", "--secure"])
def test_exact_blame_of_a_robot_that_sends_cmd_but_no_report(reap, tmp_path, secure):
    """Only the silent robot is blamed, and the match plays on: nobody downstream of its base station
    fires a watchdog of its own.

    In about half the runs the engine (or the referee) used to be co-blamed at tick 3. When the base
    station gave up, the engine, stalled on robot a/0's cmd, got it and moved on to robot a/1's, still
    stalled; it took back its announced wait and announced the new one only a second later, and the
    b robots, whose own timeouts came within that second, found it not waiting. A sender now owes a
    frame only a full timeout after it was last seen waiting (runtime/drivers.py `Reactor`).
    """
    result = play_with_a_silent_robot(reap, tmp_path, secure)
    assert result["dead"] == ["robot/a/1"], result["faults"]
    assert [f["process"] for f in result["faults"]] == ["robot/a/1"], result["faults"]


def plain_client(endpoint: str) -> zenoh.Session:
    """A zenoh client with no project code: explicit endpoint, no scouting."""
    conf = zenoh.Config()
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(conf)


def test_forged_nan_orders_are_counted_and_the_match_plays_on(reap, tmp_path):
    """Issue 15 item 7: 10 forged `order` frames with NaN fields to robot b/1, each for the tick it waits for next.

    The tester's run: the robot took them, its strategy made a NaN `cmd`, and the match stalled to ticks 0.
    Each forged frame is the next order the robot expects: it goes out when the robot's `cmd` shows that
    it has the genuine order before, ticks before the base station can send the genuine one.
    The forger is an insider with the base station's MAC key (every frame carries its sender's MAC, and a
    stranger's would be dropped as `forged` before the robot looked at it, issue 36): the NaN reaches
    the robot's validation.
    """
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    creds = tmp_path / "creds"
    proc = spawn(*MATCH, "--half-time", "10", "--seed", "6", "--match", "nanorder", "--listen", endpoint,
                 "--credentials", str(creds))  # fmt: skip
    reap.append(proc)
    wait_for(lambda: (tmp_path / "router.sock").exists(), 30, "the router socket")
    frag = json.loads((creds / "basestation-b.json5").read_text())
    bs_key = bytes.fromhex(frag["metadata"]["arena"]["keys"]["basestation/b"])
    session = plain_client(endpoint)
    try:
        # Remote only: our own forged frames must not come back to `on_order` as genuine ones.
        pub = session.declare_publisher("arena/nanorder/team/b/order/1", allowed_destination=zenoh.Locality.REMOTE)
        genuine: list[int] = []
        forged: list[int] = []
        lock = threading.Lock()

        def on_order(sample):
            with lock:
                genuine.append(msgpack.unpackb(sample.payload.to_bytes())["tick"])

        def on_cmd(sample):
            # The robot's cmd for tick t + 1 proves it has the genuine order of tick t: the forged order
            # for the next comm tick is then the very frame it expects, and the base station cannot send
            # the genuine one before the robot's next report, ticks later.
            # One frame (a map), or a batch of them (an array of the frames' bytes; schemas/README.md, "Batches").
            sent = msgpack.unpackb(sample.payload.to_bytes())
            ticks = [msgpack.unpackb(f)["tick"] for f in sent] if isinstance(sent, list) else [sent["tick"]]
            with lock:
                if len(genuine) < 2 or len(forged) >= 10 or genuine[-1] + 1 not in ticks or genuine[-1] + 1 < 200:
                    return
                nxt = genuine[-1] + (genuine[-1] - genuine[-2])
                forged.append(nxt)
            nan = float("nan")
            payload = msgpack.packb({"tick": nxt, "robot": 1, "command": "START", "spot_x": nan,
                                     "ball_valid": True, "ball_x": nan, "ball_y": nan})  # fmt: skip
            pub.put(payload, attachment=tag(bs_key, "arena/nanorder/team/b/order/1", payload))

        subs = [
            session.declare_subscriber("arena/nanorder/team/b/order/1", on_order),
            session.declare_subscriber("arena/nanorder/robot/b/1/cmd", on_cmd),
        ]
        code, result, err = finish(proc, 180)
        for sub in subs:
            sub.undeclare()
    finally:
        session.close()
    assert code == 0, err
    assert len(forged) == 10
    assert result["outcome"] == "completed", result["outcome_reasons"]
    assert result["ticks"] == 1000 and result["events"]["END_GAME"] == 1
    assert result["dead"] == [] and result["faults"] == []
    reasons = result["rejected_reasons"]
    # Every forged frame is counted once: `invalid` when it came first (a safe default stood in for it,
    # and the genuine frame after it counts as a `conflict` and takes its place), else `conflict` or
    # `out-of-sequence` (it came late). So 10 + invalid in all, and nothing else is rejected. Timed off
    # the robot's cmd, the forged frames came first in every run we made (10 invalid, 10 conflicts).
    assert set(reasons) <= {"invalid", "conflict", "out-of-sequence"}, reasons
    assert reasons.get("invalid", 0) >= 1, reasons
    assert sum(reasons.values()) == 10 + reasons["invalid"], reasons
    assert "Traceback" not in err
