"""Whole matches in one process over the memory transport: determinism, step by step."""

from __future__ import annotations

import msgspec
import pytest

from arena.runtime.config import MatchConfig
from arena.schemas.messages import World
from arena.tools.inprocess import play_in_process

decode_world = msgspec.msgpack.Decoder(World).decode


def first_difference(a: list[bytes], b: list[bytes]) -> str | None:
    for wa, wb in zip(a, b):
        if wa != wb:
            x, y = decode_world(wa), decode_world(wb)
            return f"tick {x.tick}: ball ({x.ball_x:.4f}, {x.ball_y:.4f}) vs ({y.ball_x:.4f}, {y.ball_y:.4f})"
    if len(a) != len(b):
        return f"lengths differ: {len(a)} vs {len(b)} world frames"
    return None


@pytest.fixture(scope="module")
def seed5():
    return play_in_process(MatchConfig(seed=5, half_time=3.0, link="congested-wifi"))


def test_same_seed_same_world_at_every_tick(seed5):
    _, frames = seed5
    _, again = play_in_process(MatchConfig(seed=5, half_time=3.0, link="congested-wifi"))
    diff = first_difference(frames["world"], again["world"])
    assert diff is None, f"first difference at {diff}"


def test_other_seed_other_match(seed5):
    _, frames = seed5
    _, other = play_in_process(MatchConfig(seed=6, half_time=3.0, link="congested-wifi"))
    assert first_difference(frames["world"], other["world"]) is not None


def test_every_tick_has_a_world_frame_and_the_match_flow_is_complete(seed5):
    summaries, frames = seed5
    ticks = [decode_world(w).tick for w in frames["world"]]
    assert ticks == list(range(301))
    events = summaries["referee"].extra["events"]
    for name in ("FIRST_HALF", "KICKOFF", "HALF_TIME", "SECOND_HALF", "END_GAME"):
        assert events.get(name, 0) >= 1, events
    assert summaries["referee"].extra["log"][-1]["command"] == "END_GAME"


def test_links_really_drop_under_congested_wifi(seed5):
    summaries, _ = seed5
    wifi = [s.links["wifi"] for s in summaries.values() if "wifi" in s.links]
    assert sum(w["dropped"] for w in wifi) > 0
    assert all(s.rejected == 0 and not s.dead for s in summaries.values())
