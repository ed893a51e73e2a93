"""arena.match: one entry point for either engine, a typed result, and the stepped form."""

from __future__ import annotations

import msgspec
import pytest

from arena import match
from arena.config import MatchConfig
from arena.schemas.messages import World

CFG = MatchConfig(seed=3, half_time=1.0)


def test_play_returns_the_typed_result_with_what_was_watched():
    result = match.play(CFG, watch=("world",))
    assert isinstance(result, match.MatchResult) and result.engine == "inprocess"
    worlds = [msgspec.msgpack.decode(raw, type=World) for raw in result.frames["world"]]
    assert worlds and worlds[-1].tick == result.ticks
    assert set(result.summaries) == {str(p) for p in CFG.processes()}
    assert "frames" not in result.to_dict() and "summaries" not in result.to_dict()


def test_the_digest_is_the_counted_processes():
    result = match.play(CFG)
    names = [str(p) for p in match.counted(CFG)]
    assert list(result.process_digests) == names
    assert match.combined_digest(CFG, result.process_digests) == result.digest
    recorded = CFG.replace(tap=True, live=9000)
    assert [str(p) for p in match.counted(recorded)] == names  # the recorder and the viewer never count


def test_engines_by_name():
    assert match.engine("inprocess").name == "inprocess"
    assert match.engine("processes", strict=True) == match.Processes(strict=True)
    with pytest.raises(ValueError, match="no engine"):
        match.engine("threads")
    with pytest.raises(match.MatchError, match="lockstep only"):
        match.play(CFG.replace(realtime=True))


def test_a_stepped_match_played_to_the_end_has_the_digests_of_play():
    stepped = match.InProcess().stepped(CFG, watch=("referee",))
    summaries, deadlocks = stepped.play(set())
    assert not deadlocks and stepped.frames("referee")
    digests = {name: s.digest for name, s in summaries.items()}
    assert match.combined_digest(CFG, digests) == match.play(CFG).digest
