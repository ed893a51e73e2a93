"""Whole matches of the paper's strategies look like soccer (issue 4; opt-in: -m slow).

About a minute on two cores: 10 seeds of 2 x 60 s AD vs BS and of BS vs BS, in-process
(experiments/facts.py, measured by arena.recording.analysis), in two worker processes. The numbers these bounds come from are
in docs/strategies.md ("Measured"); the bounds leave room for other seeds, not for
another kind of play.
"""

from __future__ import annotations

import pytest

from arena.config import MatchConfig
from arena.experiments.facts import many

SEEDS = range(10)


@pytest.fixture(scope="module")
def advance_vs_basic():
    return many([MatchConfig(seed=s, home="AD", away="BS", half_time=60.0) for s in SEEDS], workers=2)


@pytest.fixture(scope="module")
def basic_vs_basic():
    return many([MatchConfig(seed=s, home="BS", away="BS", half_time=60.0) for s in SEEDS], workers=2)


@pytest.mark.slow
def test_robots_do_not_drive_through_each_other_or_shove(advance_vs_basic, basic_vs_basic):
    for m in advance_vs_basic + basic_vs_basic:
        assert m.overlap_s == 0.0 and m.max_overlap_m < 0.03, m  # footprints never sink 3 cm into each other
        assert m.contact_s < 20.0, m  # [pair-s] in 120 s of play: no lasting scrums
        assert sum(t.pushing for t in m.teams) <= 6, m


@pytest.mark.slow
def test_goalkeepers_save_and_shots_come_from_both_sides(advance_vs_basic, basic_vs_basic):
    saves = sum(t.saves for m in advance_vs_basic + basic_vs_basic for t in m.teams)
    on_target = sum(t.on_target for m in advance_vs_basic + basic_vs_basic for t in m.teams)
    assert saves >= 10 and on_target >= 60, (saves, on_target)


@pytest.mark.slow
def test_basic_teams_score_against_each_other(basic_vs_basic):
    goals = [sum(m.score) for m in basic_vs_basic]
    assert sum(goals) >= 5 and sum(g > 0 for g in goals) >= 5, goals  # paper Table 1: basic teams do score


@pytest.mark.slow
def test_no_match_is_decided_by_robots_stuck_by_the_fence(advance_vs_basic, basic_vs_basic):
    for m in advance_vs_basic + basic_vs_basic:
        for t in m.teams:
            assert t.conceded_while_stuck == 0, m
            assert t.longest_stuck_s < 10.0, m
