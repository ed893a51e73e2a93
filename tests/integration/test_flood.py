"""Blame under a flood (issue 36, item 4): a stranger bursting unauthenticated frames blames nobody.

A zenoh client without credentials on a match's router (not `--secure`) puts, as fast as the
router takes them, the tester's burst (12,000 `engine/events` frames, 60,000 `world` frames,
1,200 tap batches, forged Summaries of every process and acks), again and again while the
match plays: 2 to 9 million world frames in a 2 x 60 s match on the 2-core host. Every frame is dropped
(no MAC) and the match plays exactly as without the flood. Before, 5 of 8 runs ended
`completed_with_faults`, naming processes that never failed (once all 11: "engine: its liveliness
token vanished mid-match"): the launcher took a liveliness lapse under load for a failure.
This flood on the code before the fix, three sittings: 1 of 3, at least 4 of 6, and 6 of 6 runs
ended `completed_with_faults` with such faults (the engine, a base station, a robot).

Slow suite; `ARENA_FLOOD_RUNS` runs (10 by default), each must end `completed` with `faults: []`.
"""

from __future__ import annotations

import json
import os
import threading

import msgspec
import pytest
import zenoh

from arena.config import MatchConfig
from arena.match.inprocess import play_match
from arena.runtime.session import NetConfig, open_session
from arena.schemas import messages as m
from tests.integration.helpers import spawn, wait_for
from tests.integration.test_faults import finish, wait_for_tick

RUNS = int(os.environ.get("ARENA_FLOOD_RUNS", "10"))
SPEC = {"home": "BS", "away": "BS", "half_time": 60.0, "seed": 8}
PROCESSES = ["engine", "referee", "basestation/a", "basestation/b"] + [
    f"robot/{t}/{n}" for t in "ab" for n in range(MatchConfig(**SPEC).robots)
]


@pytest.fixture(scope="module")
def honest() -> dict:
    """The same match in one process: the digest and score the flooded one must have."""
    return play_match(MatchConfig(**SPEC)).to_dict()


def flood(session: zenoh.Session, match: str, stop: threading.Event, sent: dict[str, int]) -> None:
    """The burst of the tester's campaign, without any MAC, in its proportions, again and again until
    the match ends (one burst in 100 rounds)."""
    enc = msgspec.msgpack.encode
    goal = m.BallEvent(kind="GOAL", tick=1, team="b")
    robot = m.RobotState(team="a", robot=0, x=0.0, y=0.0, theta=0.0)
    batches = {
        "engine/events": (12_000, lambda i: enc(m.EngineEvents(tick=i, events=[goal]))),
        "world": (60_000, lambda i: enc(m.World(tick=i, t=i * 0.02, ball_x=0.0, ball_y=0.0, robots=[robot]))),
        "tap/engine": (1_200, lambda i: enc(m.TapBatch(tick=i, process="engine", seq=i))),
    }
    pubs = {}
    for key in [*batches, *(f"summary/{p}" for p in PROCESSES), *(f"ack/{p}" for p in PROCESSES)]:
        pubs[key] = session.declare_publisher(f"arena/{match}/{key}", congestion_control=zenoh.CongestionControl.BLOCK)
    summary = {p: enc(m.Summary(tick=0, process=p, pid=1, digest="0" * 32, sent=0, rejected=0)) for p in PROCESSES}
    rounds = 0
    while not stop.is_set():
        for key, (n, make) in batches.items():
            for i in range((rounds % 100) * n // 100, (rounds % 100 + 1) * n // 100):
                pubs[key].put(make(i))
                sent[key] = sent.get(key, 0) + 1
        for p in PROCESSES:
            pubs[f"summary/{p}"].put(summary[p])
            pubs[f"ack/{p}"].put(b"ack")
            sent["summary"] = sent.get("summary", 0) + 1
        rounds += 1
    sent["rounds"] = rounds


@pytest.mark.slow
@pytest.mark.parametrize("run", range(RUNS))
def test_a_flood_without_credentials_blames_nobody(tmp_path, reap, honest, run):
    match_id = f"flood{run}"
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    spec = [f"--{k.replace('_', '-')}={v}" for k, v in SPEC.items()]
    proc = spawn("match", *spec, "--match", match_id, "--listen", endpoint, "--json", "--logs", str(tmp_path / "logs"))
    reap.append(proc)
    wait_for(lambda: (tmp_path / "router.sock").exists(), 60, "the router socket")
    wait_for_tick(endpoint, match_id, 100, proc)
    stop, sent = threading.Event(), {}
    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        burst = threading.Thread(target=flood, args=(session, match_id, stop, sent), daemon=True)
        burst.start()
        try:
            code, result, err = finish(proc, 400)
        finally:
            stop.set()
            burst.join(30)
    assert sent["rounds"] >= 100, ("at least the tester's whole burst, mid-match", sent)
    assert code == 0, err[-3000:]
    assert result["outcome"] == "completed" and result["faults"] == [], (
        result["faults"],
        result["outcome_reasons"],
        json.dumps(sent),
    )
    assert result["dead"] == [] and result["ticks"] == honest["ticks"]
    assert result["digest"] == honest["digest"] and result["score"] == honest["score"]
    assert result["forged"].get("engine/events", 0) > 0, result["rejected_reasons"]
