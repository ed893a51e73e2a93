"""A stranger on a match that is not `--secure` forges frames ahead of the genuine ones (issue 36).

Without `--secure` anybody who reaches the router may put on any key. Before every frame
carried its sender's MAC, the base stations took the first `referee` frame of each tick (a
forged PENALTY stood in for the genuine one), the engine the first `cmd`, the robots the first
`order`, the base stations the first `report`: a 3:0 match ended 0:20, and a genuine frame that
came after a forged one was counted as `out-of-sequence`, so hardly anything was flagged.

Here the stranger puts a whole match's worth of well-formed `referee`, `cmd`, `order` and
`report` frames, every one for a tick its receiver will expect, while every process but robot
a/0 waits at the start barrier; then, once every forged frame has arrived (`SENTINELS`), a/0
starts and the match plays. It must play exactly as the unforged one (the golden digests, so the same score),
and every forged frame is counted by every process subscribed to its key, per key, with one
"possible spoofing on KEY" line per key during the match.
"""

from __future__ import annotations

import json
import subprocess

import zenoh

from arena.config import MatchConfig
from arena.match.inprocess import play_match
from arena.runtime.session import NetConfig, open_session
from arena.schemas import messages as m
from tests.integration.helpers import ARENA, wait_for
from tests.integration.test_fuzz import CFG, GOLDEN, TOTAL, Launcher, stacks_after

TEAMS = ("a", "b")
ROBOTS = range(CFG["robots"])
POSE = m.Pose(x=0.5, y=-0.5, theta=0.1)


# The signal that every forged frame is in (no fixed wait): the last frames put are one on a key of
# each receiver that nothing forged reached before. Zenoh keeps one session's puts in order per link,
# so when a receiver counts that one as forged, and says so with its spoofing token (`spoofing/<process>
# /<key>`, at the start barrier too), every frame put before it has reached that receiver.
SENTINELS = {
    "robot/b/1/cmd": "engine",
    "team/a/report/1": "basestation/a",
    "team/b/report/1": "basestation/b",
    **{f"robot/{t}/{n}/sense": f"robot/{t}/{n}" for t in TEAMS for n in ROBOTS if (t, n) != ("a", 0)},
}


def sentinel_frames() -> dict[str, tuple[int, list[bytes]]]:
    """key -> (1 receiver, one forged frame for its first tick)."""
    out: dict[str, tuple[int, list[bytes]]] = {}
    for key in SENTINELS:
        if key.endswith("/cmd"):
            out[key] = (1, [m.encode(m.Cmd(tick=0, vx=-5.0))])
        elif "/report/" in key:
            out[key] = (1, [m.encode(m.Report(tick=0, robot=int(key[-1]), pose=POSE))])
        else:
            out[key] = (1, [m.encode(m.Sense(tick=0, pose=POSE))])
    return out


def forged_frames() -> dict[str, tuple[int, list[bytes]]]:
    """key -> (how many waiting processes receive it, the forged frames, every tick of its schedule);
    the keys of `SENTINELS` come last, with one frame each."""
    penalty = [m.RefCommand(name="PENALTY", team="b")]
    out: dict[str, tuple[int, list[bytes]]] = {
        "referee": (
            3,  # the engine, both base stations
            [
                m.encode(
                    m.Referee(
                        tick=t, stage="FIRST_HALF", command="PENALTY", command_team="b", score_b=20, commands=penalty
                    )
                )  # fmt: skip
                for t in range(0, TOTAL + 1, 5)
            ],
        )
    }
    for t in TEAMS:
        for n in ROBOTS:
            out[f"robot/{t}/{n}/cmd"] = (1, [m.encode(m.Cmd(tick=k, vx=-5.0, omega=3.0)) for k in range(TOTAL + 1)])
            out[f"team/{t}/report/{n}"] = (
                1,
                [m.encode(m.Report(tick=k, robot=n, pose=POSE)) for k in range(0, TOTAL + 1, 5)],
            )
            if (t, n) != ("a", 0):  # nobody receives a/0's orders until a/0 starts
                out[f"team/{t}/order/{n}"] = (
                    1,
                    [m.encode(m.Order(tick=k, robot=n, command="STOP")) for k in range(1, TOTAL + 1, 5)],
                )
    return {k: v for k, v in out.items() if k not in SENTINELS} | sentinel_frames()


def test_a_stranger_forging_frames_ahead_changes_nothing_and_every_frame_is_counted(tmp_path, reap):
    match_id = "forgery"
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    launcher = Launcher(reap, tmp_path / "logs", "match", "--home", CFG["home"], "--away", CFG["away"],
                        "--robots", str(CFG["robots"]), "--half-time", str(CFG["half_time"]),
                        "--seed", str(CFG["seed"]), "--link", CFG["link"], "--external", "a/0",
                        "--match", match_id, "--listen", endpoint, "--json")  # fmt: skip
    command = launcher.line("arena run robot", 60).split()
    frames = forged_frames()
    with stacks_after(240), open_session(NetConfig(mode="peer", connect=(endpoint,))) as session:
        alive: set[str] = set()
        sub = session.liveliness().declare_subscriber(
            f"arena/{match_id}/alive/**", lambda s: alive.add(str(s.key_expr).split("/alive/")[1]), history=True
        )
        others = 2 * CFG["robots"] + 3
        wait_for(lambda: len(alive) >= others, 120, "every other process at its start barrier")
        sub.undeclare()
        wait_for(lambda: len(list(session.info.peers_zid())) >= others, 30, "a direct link to every other process")
        tokens: set[str] = set()
        spoofing = session.liveliness().declare_subscriber(
            f"arena/{match_id}/spoofing/**", lambda s: tokens.add(str(s.key_expr).split("/spoofing/")[1]), history=True
        )
        for key, (_, payloads) in frames.items():  # the sentinels last
            pub = session.declare_publisher(
                f"arena/{match_id}/{key}",
                congestion_control=zenoh.CongestionControl.BLOCK,
                reliability=zenoh.Reliability.RELIABLE,
            )
            for payload in payloads:
                pub.put(payload)  # no attachment: the stranger has no key
            pub.undeclare()
        # Every forged frame is in its receivers' queues before the genuine ones come.
        want_tokens = {f"{p.replace('/', '-')}/{key}" for key, p in SENTINELS.items()}
        wait_for(lambda: want_tokens <= tokens, 120, "every receiver's spoofing token for its sentinel")
        spoofing.undeclare()
        with open(launcher.logs / "external_robot_a_0.log", "wb") as log:
            reap.append(subprocess.Popen([*ARENA, *command[1:]], stdout=log, stderr=subprocess.STDOUT))
        out = launcher.finish(120)
    err = "".join(launcher.err)
    assert launcher.proc.returncode == 0, err
    result = json.loads(out)
    assert result["outcome"] == "completed" and result["faults"] == [], (result["faults"], result["outcome_reasons"])
    assert result["process_digests"] == GOLDEN["digests"], "a forged frame took a genuine one's place"
    honest = play_match(MatchConfig(**CFG)).to_dict()
    assert result["score"] == honest["score"] and result["digest"] == honest["digest"]
    want = {key: receivers * len(payloads) for key, (receivers, payloads) in frames.items()}
    assert result["forged"] == dict(sorted(want.items())), result["rejected_reasons"]
    assert result["rejected_reasons"] == {"forged": sum(want.values())}, "no conflict, no out-of-sequence"
    assert result["conflicts"] == {}
    # Said during the match, once per key (a spoofing token from its receivers), and with the counts at its end.
    for key in frames:
        assert sum(f"possible spoofing on {key} (forged or" in line for line in launcher.err) == 1, (key, err)
        said = f"{want[key]} forged message" + ("s" if want[key] != 1 else "")  # counted per message
        assert f"possible spoofing on {key} ({said})" in err, (key, err)
