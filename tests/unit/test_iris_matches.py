"""Whole matches of the paper's strategies (opt-in: -m slow)."""

from __future__ import annotations

import pytest

from arena.runtime.config import MatchConfig
from arena.tools.launch.inprocess import play_in_process


@pytest.mark.slow
def test_advance_dynamic_beats_basic_static_over_ten_seeds():
    """Paper 2 Table 1: AD vs BS won 9, drew 1. Here: >= 7 wins and <= 1 loss in 2 x 60 s."""
    results = []
    for seed in range(10):
        summaries, _ = play_in_process(MatchConfig(seed=seed, home="AD", away="BS", half_time=60.0), watch=())
        results.append(tuple(summaries["referee"].extra["score"]))
    wins = sum(a > b for a, b in results)
    losses = sum(a < b for a, b in results)
    assert wins >= 7 and losses <= 1, results
