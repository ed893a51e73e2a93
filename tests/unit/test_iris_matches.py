"""Whole matches of the paper's strategies (opt-in: -m slow)."""

from __future__ import annotations

import pytest

from arena.config import MatchConfig
from arena.match.inprocess import play_in_process


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="since static roles keep their Fig. 5 areas and the push guard predicts opponents, AD v BS in "
    "2 x 60 s gives 5 W 5 D 0 L (BS's keeper saved 8 of 17 shots; docs/strategies.md); over 2 x 5 min AD wins 7 of 10",
)
def test_advance_dynamic_beats_basic_static_over_ten_seeds():
    """Paper 2 Table 1: AD vs BS won 9, drew 1. Here: >= 7 wins and <= 1 loss in 2 x 60 s."""
    results = []
    for seed in range(10):
        summaries, _ = play_in_process(MatchConfig(seed=seed, home="AD", away="BS", half_time=60.0), watch=())
        results.append(tuple(summaries["referee"].extra["score"]))
    wins = sum(a > b for a, b in results)
    losses = sum(a < b for a, b in results)
    assert wins >= 7 and losses <= 1, results
