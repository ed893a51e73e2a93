"""Measured cases of issues 15 and 20 with forged or missing frames: forged NaN orders.

Real processes over real zenoh. The forged orders come from a plain zenoh
client, encoded with plain msgpack.
"""

from __future__ import annotations

import json

import msgpack
import zenoh

from tests.integration.helpers import spawn, wait_for

MATCH = ("match", "--home", "BS", "--away", "BS", "--json")


def finish(proc, timeout: float = 300) -> tuple[int, dict | None, str]:
    out, err = proc.communicate(timeout=timeout)
    return proc.returncode, (json.loads(out) if out.strip() else None), err


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
    Each forged frame goes out as soon as the genuine order before it arrives; when it reaches the robot
    first it stands in (counted `invalid`, replaced by the previous order), else it loses the race to the
    base station's frame and is counted as such. Which of the two happens depends on the OS scheduler.
    """
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    proc = spawn(*MATCH, "--half-time", "10", "--seed", "6", "--match", "nanorder", "--listen", endpoint)
    reap.append(proc)
    wait_for(lambda: (tmp_path / "router.sock").exists(), 30, "the router socket")
    session = plain_client(endpoint)
    try:
        pub = session.declare_publisher("arena/nanorder/team/b/order/1")
        genuine: list[int] = []
        forged: list[int] = []

        def answer(sample):
            tick = msgpack.unpackb(sample.payload.to_bytes())["tick"]
            genuine.append(tick)
            if len(genuine) >= 2 and len(forged) < 10 and tick >= 200:
                nxt = tick + (genuine[-1] - genuine[-2])
                nan = float("nan")
                pub.put(msgpack.packb({"tick": nxt, "robot": 1, "command": "START", "spot_x": nan,
                                       "ball_valid": True, "ball_x": nan, "ball_y": nan}))  # fmt: skip
                forged.append(nxt)

        sub = session.declare_subscriber("arena/nanorder/team/b/order/1", answer)
        code, result, err = finish(proc, 180)
        sub.undeclare()
    finally:
        session.close()
    assert code == 0, err
    assert len(forged) == 10
    assert result["outcome"] == "completed", result["outcome_reasons"]
    assert result["ticks"] == 1000 and result["events"]["END_GAME"] == 1
    assert result["dead"] == [] and result["faults"] == []
    reasons = result["rejected_reasons"]
    # Every forged frame is counted: `invalid` when it came first (a safe default stood in for it, and the
    # genuine frame after it counts too), else `conflict` or `out-of-sequence` (it lost the race against
    # the base station). Nothing but these is rejected, and nothing stalled.
    assert set(reasons) <= {"invalid", "conflict", "out-of-sequence"}, reasons
    assert sum(reasons.values()) >= 10, reasons
    assert "Traceback" not in err
