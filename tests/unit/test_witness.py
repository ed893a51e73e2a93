"""The launcher's digest check of an external process (match/witness.py), and the digest layout the README gives."""

from __future__ import annotations

import hashlib

import msgspec

from arena.match.witness import Witness, digest_update
from arena.runtime.lockstep import Outbound
from arena.schemas.keys import DEFAULT_PERIODS, Keys
from arena.schemas.messages import Cmd, Pose, Report

PERIODS = dict(DEFAULT_PERIODS)


class Callbacks:
    """Test double: keeps the witness's callbacks so the test can feed them frames, each through the
    MAC check the transport makes (`callbacks[key](payload, attachment)`) when it has a keyring."""

    def __init__(self, keyring=None) -> None:
        self.callbacks: dict[str, object] = {}
        self.keyring = keyring

    def subscribe_callback(self, key: str, callback, verify=None) -> None:
        def deliver(payload: bytes, attachment: bytes | None = None) -> None:
            if verify is None or verify(payload, attachment):
                callback(payload)

        self.callbacks[key] = deliver


def _sent_by_a_node() -> tuple[str, list[tuple[str, bytes]]]:
    """What runtime/lockstep.py puts and digests for robot a/1 over a few ticks."""
    digest = hashlib.blake2b(digest_size=16)
    wire: list[tuple[str, bytes]] = []
    cmd = Outbound("arena/w/robot/a/1/cmd", "robot/a/1/cmd", lambda p: wire.append(("robot/a/1/cmd", p)), digest)
    rep = Outbound("arena/w/team/a/report/1", "team/a/report/1", lambda p: wire.append(("team/a/report/1", p)), digest)
    for k in range(7):
        cmd.send(Cmd(tick=k, mode="wheels", wheels=[0.0] * 4))
        if k % 5 == 0:
            rep.send(Report(tick=k, robot=1, pose=Pose(x=1.0, y=2.0, theta=0.5)))
    return digest.hexdigest(), wire


def test_the_readme_digest_layout_is_the_one_the_processes_compute():
    expected, wire = _sent_by_a_node()
    h = hashlib.blake2b(digest_size=16)
    for rel, payload in wire:
        digest_update(h, rel, payload)
    assert h.hexdigest() == expected


def test_the_witness_accepts_the_true_digest_and_refuses_another():
    expected, wire = _sent_by_a_node()
    tr = Callbacks()
    w = Witness(tr, Keys("w"), robots=3, watched={"robot/a/1"}, periods=PERIODS)
    assert set(tr.callbacks) == {"arena/w/robot/a/1/cmd", "arena/w/team/a/report/1"}
    for rel, payload in wire:
        tr.callbacks[f"arena/w/{rel}"](payload)
    assert w.check("robot/a/1", "0" * 32, dead=[]) is not None
    assert w.verified() == []
    assert w.check("robot/a/1", expected, dead=[]) is None
    assert w.verified() == ["robot/a/1"]
    assert w.check("engine", "0" * 32, dead=[]) is None, "only watched processes are checked"


def test_a_process_that_muted_a_key_for_a_dead_receiver_is_accepted_unverified():
    _, wire = _sent_by_a_node()
    tr = Callbacks()
    w = Witness(tr, Keys("w"), robots=3, watched={"robot/a/1"}, periods=PERIODS)
    for rel, payload in wire[:3]:
        tr.callbacks[f"arena/w/{rel}"](payload)
    assert w.check("robot/a/1", "1" * 32, dead=["basestation/a"]) is None
    assert w.verified() == []


def test_garbage_and_frames_of_future_ticks_from_others_do_not_count_and_a_duplicate_tick_is_unverifiable():
    expected, wire = _sent_by_a_node()
    tr = Callbacks()
    w = Witness(tr, Keys("w"), robots=3, watched={"robot/a/1"}, periods=PERIODS)
    cmd = tr.callbacks["arena/w/robot/a/1/cmd"]
    cmd(b"\x93garbage")  # not a Cmd
    cmd(msgspec.msgpack.encode(Cmd(tick=40)))  # a tick it has not reached
    for rel, payload in wire:
        tr.callbacks[f"arena/w/{rel}"](payload)
    assert w.check("robot/a/1", expected, dead=[]) is None and w.verified() == ["robot/a/1"]
    cmd(msgspec.msgpack.encode(Cmd(tick=2, vx=3.0)))  # a forger's frame for a tick already sent
    assert w.check("robot/a/1", "2" * 32, dead=[]) is None, "unverifiable, not refused"


def test_batched_cmds_that_reach_the_wire_after_a_later_report_are_put_back_in_send_order():
    """With a perception latency a robot holds its `cmd` frames for a batch, while its `report` goes out at once."""
    digest = hashlib.blake2b(digest_size=16)
    wire: list[tuple[str, bytes]] = []
    cmd = Outbound("arena/w/robot/a/1/cmd", "robot/a/1/cmd", lambda p: wire.append(("robot/a/1/cmd", p)), digest)
    rep = Outbound("arena/w/team/a/report/1", "team/a/report/1", lambda p: wire.append(("team/a/report/1", p)), digest)
    cmd.batch(3, 11)
    for k in range(12):
        cmd.send(Cmd(tick=k, vx=0.1 * k))
        if k % 5 == 0:
            rep.send(Report(tick=k, robot=1, pose=Pose(x=1.0, y=2.0, theta=0.5)))
    assert [rel for rel, _ in wire][:2] == ["team/a/report/1", "robot/a/1/cmd"], "report 0 overtook cmd 0"
    tr = Callbacks()
    w = Witness(tr, Keys("w"), robots=3, watched={"robot/a/1"}, periods=PERIODS)
    for rel, payload in wire:
        tr.callbacks[f"arena/w/{rel}"](payload)
    assert w.frames["robot/a/1"] == 12 + 3
    assert w.check("robot/a/1", digest.hexdigest(), dead=[]) is None
    assert w.verified() == ["robot/a/1"]


def test_a_forged_frame_ahead_of_the_genuine_one_never_enters_the_digest():
    """Issue 36: with the launcher's keyring, a stranger's frame for the very tick the external sends next is
    dropped for its missing MAC; before, it took the tick and the genuine Summary was refused as forged."""
    from arena.runtime.mac import Keyring, tag

    key = bytes(range(32))
    expected, wire = _sent_by_a_node()
    tr = Callbacks(Keyring("launcher", {"robot/a/1": key}))
    w = Witness(tr, Keys("w"), robots=3, watched={"robot/a/1"}, periods=PERIODS)
    tr.callbacks["arena/w/robot/a/1/cmd"](msgspec.msgpack.encode(Cmd(tick=0, vx=-5.0)))  # no MAC
    for rel, payload in wire:
        tr.callbacks[f"arena/w/{rel}"](payload, tag(key, f"arena/w/{rel}", payload))
    assert w.check("robot/a/1", expected, dead=[]) is None and w.verified() == ["robot/a/1"]
