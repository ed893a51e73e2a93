"""The typed match result: its fields are the keys of `arena match --json`, in order
(tests/integration/test_match.py checks README's table against the printed keys)."""

from __future__ import annotations

from arena.config import MatchConfig
from arena.match import inprocess
from arena.match.result import MatchResult


def test_the_dict_has_the_fields_in_order_and_leaves_out_what_the_engine_did_not_set():
    result = inprocess.play_match(MatchConfig(seed=3, half_time=1.0))
    out = result.to_dict()
    fields = list(MatchResult.__struct_fields__)
    assert list(out) == [f for f in fields if f in out]
    assert {"pid", "deadlocks", "launch"} <= set(out) and not {"secure", "services", "logs"} & set(out)
    assert out["engine"] == "inprocess" and out["digest"] == result.digest and len(out["digest"]) == 32
