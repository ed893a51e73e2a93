"""Perception latency (the model) and batches of frames (a transport detail).

A robot acting at tick k sees the `sense` of tick k - L (`timing.perception_latency`);
with L >= 2 the engine and the robots put up to L ticks of `sense`/`cmd` frames in
one message (`timing.batch`). What any process decides depends on L only: the
batch size must leave every digest as it is.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib

import msgpack
import pytest

from arena.config import ConfigError, MatchConfig
from arena.match.inprocess import play_in_process
from arena.runtime.lockstep import MAX_BATCH, Outbound
from arena.schemas.messages import Cmd, encode
from tests.unit.test_lockstep import KEY, Harness


def _outbound(size: int, last: int):
    digest, wire = hashlib.blake2b(), []
    ob = Outbound(KEY, "robot/a/1/cmd", wire.append, digest)
    ob.batch(size, last)
    for k in range(last + 1):
        ob.send(Cmd(tick=k, vx=k / 10))
    return digest.hexdigest(), wire


def test_a_batch_holds_the_frames_of_aligned_ticks_and_the_digest_is_unchanged():
    one, singles = _outbound(1, 7)
    three, batches = _outbound(3, 7)
    assert one == three  # the digest covers frames, not messages
    assert len(singles) == 8 and len(batches) == 3  # ticks 0-2, 3-5, 6-7 (the last tick ends a batch)
    frames = [f for b in batches for f in msgpack.unpackb(b)]  # plain msgpack: an array of bin
    assert frames == singles
    assert [len(msgpack.unpackb(b)) for b in batches] == [3, 3, 2]


def test_an_inbound_takes_a_batch_as_its_frames_in_order():
    h = Harness(lag=1)
    try:
        _, batches = _outbound(3, 7)
        for raw in batches:
            h.put(raw)
        h.inbound.sync(8)
        assert [c.tick for c in h.inbound.take(8)] == list(range(8))
        assert h.rej.total == 0
    finally:
        h.close()


@pytest.mark.parametrize(
    "bad",
    [
        msgpack.packb([]),  # empty
        msgpack.packb([1, 2]),  # not frames' bytes
        msgpack.packb([encode(Cmd(tick=0))] * (MAX_BATCH + 1)),  # too long
        b"\x92\xc4",  # cut short
    ],
)
def test_a_bad_batch_is_rejected_whole_counted_and_the_link_goes_on(bad):
    h = Harness(lag=1)
    try:
        h.put(bad)
        h.put(msgpack.packb([b"garbage", encode(Cmd(tick=0)), encode(Cmd(tick=5))]))
        h.put(encode(Cmd(tick=1)))
        h.inbound.sync(2)
        assert h.rej.by_reason["malformed"] == 2  # the bad batch, then one bad frame in a good one
        assert h.rej.by_reason["out-of-sequence"] == 1  # tick 5 after tick 0
        assert [c.tick for c in h.inbound.take(2)] == [0, 1]
    finally:
        h.close()


@pytest.mark.parametrize(("latency", "batch"), [(-1, 0), (26, 0), (2, 3), (0, 2), (3, -1)])
def test_impossible_latencies_and_batches_are_refused(latency, batch):
    timing = dataclasses.replace(MatchConfig().timing, perception_latency=latency, batch=batch)
    with pytest.raises(ConfigError, match="perception-latency|batch"):
        MatchConfig(timing=timing).validate()


def test_frames_per_message_is_the_latency_unless_given_and_one_in_real_time():
    timing = dataclasses.replace(MatchConfig().timing, perception_latency=3)
    assert timing.frames_per_message() == 3
    assert dataclasses.replace(timing, batch=2).frames_per_message() == 2
    assert timing.frames_per_message(realtime=True) == 1
    assert dataclasses.replace(timing, perception_latency=0).frames_per_message() == 1


@functools.cache  # (0, 1) is every latency's "another latency": played once
def _digests(latency: int, batch: int) -> dict[str, str]:
    timing = dataclasses.replace(MatchConfig().timing, perception_latency=latency, batch=batch)
    cfg = MatchConfig(home="AD", away="BS", half_time=2.0, seed=5, link="congested-wifi", timing=timing)
    summaries, _ = play_in_process(cfg, watch=())
    assert summaries["engine"].tick == cfg.total_ticks and not any(s.dead for s in summaries.values())
    return {name: s.digest for name, s in summaries.items()}


@pytest.mark.parametrize("latency", [2, 3, 16])
def test_the_batch_size_is_a_transport_detail_and_the_latency_is_the_model(latency):
    # 16: a batch of 16 cmd frames held a robot's cmd of tick 1 back while the robot waited for
    # an order of tick 7, which waited (referee, engine events) for the engine to pass tick 1:
    # a deadlock, until a node's batches were put whenever it is about to wait.
    ones = _digests(latency, 1)
    assert _digests(latency, latency) == ones
    assert _digests(0, 1)["engine"] != ones["engine"]  # another latency: robots decide otherwise


@pytest.mark.parametrize("latency", [6, 7, 12, 25])
@pytest.mark.parametrize(("comm", "referee"), [(5, 5), (1, 1), (10, 3)])
def test_no_latency_batch_or_period_deadlocks(latency, comm, referee):
    """The old aligned batches deadlocked from L = 6 on (196 of 376 such settings). Batches of L, as a
    distributed match puts them (in process they are only put when `timing.batch` asks)."""
    timing = dataclasses.replace(
        MatchConfig().timing, perception_latency=latency, comm_period=comm, referee_period=referee, batch=latency
    )
    cfg = MatchConfig(home="AD", away="BS", half_time=1.0, seed=latency, timing=timing)
    summaries, _ = play_in_process(cfg, watch=())
    assert summaries["engine"].tick == cfg.total_ticks
    assert not any(s.dead for s in summaries.values())


def test_in_process_frames_go_one_per_message_unless_a_batch_size_is_asked():
    """No wire in a cooperative match: `timing.batch` 0 (L) puts one frame per message there."""
    from arena.match.inprocess import Stepped

    def batching(batch: int) -> set[bool]:
        timing = dataclasses.replace(MatchConfig().timing, perception_latency=3, batch=batch)
        nodes = Stepped(MatchConfig(home="AD", away="BS", timing=timing)).nodes.values()
        return {n.cmd_out.batching for n in nodes if n.name.startswith("robot/")}

    assert batching(0) == {False}
    assert batching(3) == {True}
