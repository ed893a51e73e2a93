"""A stranger on the router of a live session (`--live`, `--realtime`), without `--secure`, puts
`operator` and `control` frames and answers the `config` query (issue 45).

Before these carried their sender's MAC, a plain zenoh client's `GOAL b` on `operator` made a
2:3 match 0:30 (`--live`) or 0:40 (`--realtime`), one `control` frame `{"seq": 2**62, "paused":
true}` held a `--live` match paused for good, and a robot started by hand took its configuration
from whoever answered first (a stranger's `"home": "policy:/some/file.pkl"`). Now none of it
changes a score or a digest, and every frame and answer the stranger sent is counted as forged on
its key, by each of its receivers.

How the counts are made exact: robot a/0 is left `--external`, so every other process has
subscribed and waits at the start barrier while the stranger puts; after its frames it puts one
more without a MAC on a key of each receiver that nothing forged reached before, `SENTINELS`
(zenoh keeps one session's puts in order per link). A receiver counts that one as it takes it in
and says so with its spoofing token (runtime/node.py `announce_spoofing`): every earlier frame has
reached it. In lockstep that is at the barrier (the links' receive callbacks); in real time the
receivers read their links as they play, and the operator frames with them, in the same tick.
Then a/0 starts, with its own credentials, and asks for the configuration: the stranger answers
every query, the robot counts each answer and plays the engine's.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import subprocess
import threading

import pytest
import zenoh

from arena.config import MatchConfig
from arena.match.inprocess import play_match
from arena.recording.reader import load
from arena.runtime.session import NetConfig, open_session
from arena.schemas import messages as m
from tests.integration.helpers import ARENA, descendants, free_port, wait_for
from tests.integration.test_fuzz import CFG, GOLDEN, Launcher, stacks_after

OPERATOR_FRAMES = 20
CONTROL_FRAMES = 10
# key -> the receivers that count its one sentinel frame (as its first forged frame on that key)
SENTINELS = {"referee": ("engine", "basestation/a", "basestation/b"), "engine/events": ("referee",)}


def operator_frames() -> list[bytes]:
    """A stranger's referee decisions and teleports: a goal for b, a NaN teleport, an absurd seq."""
    goal, nan = m.RefereeOverride(command="GOAL", team="b"), m.TeleportBall(x=math.nan, y=0.0)
    seqs = [*range(1, OPERATOR_FRAMES), 2**62]
    return [m.encode(m.Operator(seq=s, actions=[goal, nan])) for s in seqs]


def control_frames() -> list[bytes]:
    """The frame that paused a --live match for good, and more like it."""
    return [m.encode(m.Control(tick=0, seq=2**62 - i, paused=True)) for i in range(CONTROL_FRAMES)]


def sentinel_frames() -> dict[str, bytes]:
    referee = m.Referee(tick=0, stage="FIRST_HALF", command="GOAL", command_team="b", score_b=30)
    return {"referee": m.encode(referee), "engine/events": m.encode(m.EngineEvents(tick=4, events=[]))}


def put_all(session, match_id: str, rel: str, payloads: list[bytes]) -> None:
    pub = session.declare_publisher(
        f"arena/{match_id}/{rel}",
        congestion_control=zenoh.CongestionControl.BLOCK,
        reliability=zenoh.Reliability.RELIABLE,
    )
    wait_for(lambda: pub.matching_status.matching, 60, f"a subscriber of {rel}")
    for payload in payloads:
        pub.put(payload)  # no attachment: the stranger has no key
    pub.undeclare()


PLAYED: dict[str, dict] = {}


def play_with_a_stranger(mode: str, tmp_path, reap) -> dict:
    """Play the golden match (tests/golden/digests.json) in `mode` with the stranger on its router, once."""
    if mode in PLAYED:
        return PLAYED[mode]
    match_id = f"stranger-{mode}"
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    flags = (
        ["--live", str(free_port()), "--pace", "0"]
        if mode == "live"
        else ["--realtime", "--record", str(tmp_path / "rt.mcap")]
    )
    launcher = Launcher(reap, tmp_path / "logs", "match", "--home", CFG["home"], "--away", CFG["away"],
                        "--robots", str(CFG["robots"]), "--half-time", str(CFG["half_time"]),
                        "--seed", str(CFG["seed"]), "--link", CFG["link"], "--external", "a/0",
                        "--match", match_id, "--listen", endpoint, "--json", *flags)  # fmt: skip
    command = launcher.line("arena run robot", 60).split()
    bogus = MatchConfig(**{**CFG, "home": "policy:/nonexistent/stranger.pkl", "half_time": 1.0}).to_json().encode()
    answers = [0]

    def answer(query: zenoh.Query) -> None:
        answers[0] += 1
        query.reply(query.key_expr, bogus)  # no attachment: the stranger has no key

    # Two sessions of the stranger's: a peer with direct links to every process puts (as the fuzzer
    # does), and a client of the router answers: the router knows a client's queryable before robot
    # a/0 connects, so a/0's first query reaches it (a peer's, learnt over a direct link a/0 had not
    # opened yet, missed the first query now and then, and the engine's answer ended the asking).
    with (
        stacks_after(300),
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as session,
        open_session(NetConfig(mode="client", connect=(endpoint,))) as answering,
    ):
        alive: set[str] = set()
        sub = session.liveliness().declare_subscriber(
            f"arena/{match_id}/alive/**", lambda s: alive.add(str(s.key_expr).split("/alive/")[1]), history=True
        )
        waiting = {"engine", "referee", "basestation/a", "basestation/b"}
        wait_for(lambda: waiting <= alive, 120, "every other process at its start barrier")
        sub.undeclare()
        wait_for(lambda: len(list(session.info.peers_zid())) >= len(waiting), 30, "a direct link to each")
        queryable = answering.declare_queryable(f"arena/{match_id}/config", answer)
        tokens: set[str] = set()
        spoofing = session.liveliness().declare_subscriber(
            f"arena/{match_id}/spoofing/**", lambda s: tokens.add(str(s.key_expr).split("/spoofing/")[1]), history=True
        )
        put_all(session, match_id, "operator", operator_frames())
        if mode == "live":  # in real time nobody listens on `control`: there is no pacer
            put_all(session, match_id, "control", control_frames())
        for rel, payload in sentinel_frames().items():
            put_all(session, match_id, rel, [payload])
        want = {f"{p.replace('/', '-')}/{rel}" for rel, receivers in SENTINELS.items() for p in receivers}
        if mode == "live":  # the links' callbacks count them at the barrier
            wait_for(lambda: want <= tokens, 120, "every receiver's spoofing token for its sentinel")
        with open(launcher.logs / "external_robot_a_0.log", "wb") as log:
            robot = subprocess.Popen([*ARENA, *command[1:]], stdout=log, stderr=subprocess.STDOUT)
        reap.append(robot)
        if mode == "realtime":  # read with the operator frames, in the same tick, as they play
            wait_for(lambda: want <= tokens, 120, "every receiver's spoofing token for its sentinel")
        out = launcher.finish(180)
        robot.wait(30)
        queryable.undeclare()
        spoofing.undeclare()
    assert launcher.proc.returncode == 0, "".join(launcher.err)
    PLAYED[mode] = {
        "result": json.loads(out),
        "err": "".join(launcher.err),
        "answers": answers[0],
        "robot_log": (launcher.logs / "external_robot_a_0.log").read_text(),
        "mcap": str(tmp_path / "rt.mcap") if mode == "realtime" else None,
    }
    return PLAYED[mode]


@pytest.fixture(scope="module")
def honest() -> dict:
    return play_match(MatchConfig(**CFG)).to_dict()


_lock = threading.Lock()


@pytest.fixture(params=["live", "realtime"])
def played(request, tmp_path_factory):
    """Each mode's match, played once for every test of this module that asks for it."""
    mode = request.param
    with _lock:
        if mode not in PLAYED:
            reap: list[subprocess.Popen] = []
            try:
                play_with_a_stranger(mode, tmp_path_factory.mktemp(mode), reap)
            finally:
                for p in reap:  # as the `reap` fixture does (tests/integration/conftest.py)
                    if p.poll() is None:
                        for d in descendants(p.pid):
                            with contextlib.suppress(ProcessLookupError):
                                os.kill(d, signal.SIGKILL)
                        p.kill()
                    p.communicate()
    return mode, PLAYED[mode]


def test_nothing_a_stranger_sent_changed_the_score_or_a_digest(played, honest):
    mode, p = played
    result = p["result"]
    assert result["outcome"] == "completed" and result["faults"] == [], (result["faults"], result["outcome_reasons"])
    assert all(e.get("cause") != "operator" for e in result.get("referee_log", [])), "no forced referee command"
    if mode == "live":  # lockstep: exactly the match without the stranger
        assert result["process_digests"] == GOLDEN["digests"] and result["digest"] == honest["digest"]
        assert result["score"] == honest["score"]
    else:  # real time plays as the wall clock lets it: nothing of the stranger's was applied
        summaries = load(p["mcap"]).summaries
        assert summaries["engine"].extra["operator"] == [] and summaries["referee"].extra["operator"] == []
        assert result["score"][1] < OPERATOR_FRAMES, result["score"]


def test_every_operator_frame_is_counted_as_forged_by_the_engine_and_the_referee(played):
    _, p = played
    assert p["result"]["forged"]["operator"] == 2 * OPERATOR_FRAMES, p["result"]["forged"]
    assert "possible spoofing on operator" in p["err"]


def test_every_control_frame_is_counted_as_forged_and_the_match_was_never_held(played):
    mode, p = played
    if mode != "live":
        pytest.skip("only a --live lockstep match has a pacer that listens on control")
    assert p["result"]["forged"]["control"] == CONTROL_FRAMES, p["result"]["forged"]
    assert p["result"]["ticks"] == int(2 * CFG["half_time"] / 0.02)
    assert "possible spoofing on control" in p["err"]


def test_every_config_answer_is_counted_as_forged_by_the_robot_that_asked(played):
    _, p = played
    result = p["result"]
    assert p["answers"] >= 1 and result["forged"]["config"] == p["answers"], (p["answers"], result["forged"])
    assert "stranger.pkl" not in p["robot_log"] and result["half_time"] == CFG["half_time"]
    assert "robot/a/0" in result["digests_verified"], "the external robot played the engine's configuration"
    # and the sentinels, each once by each of its receivers
    assert {k: result["forged"][k] for k in SENTINELS} == {k: len(r) for k, r in SENTINELS.items()}
