"""`arena facts` says how far it is on stderr, one line per match off a terminal, in any order
the workers finish; the results come back in the order asked for."""

from __future__ import annotations

from arena.config import MatchConfig
from arena.experiments.facts import many


def test_one_line_per_match_and_results_in_order(capfd):
    cfgs = [MatchConfig(seed=s, half_time=1.0, home="AD", away="BS") for s in (5, 6)]
    facts = many(cfgs, workers=2, progress=True)
    err = capfd.readouterr().err.splitlines()
    assert sorted(line.split("]")[0] for line in err) == ["[1/2", "[2/2"]
    assert sorted(line.split(": ")[0].split()[-1] for line in err) == ["5", "6"]
    assert [m.seed for m in facts] == [5, 6]


def test_silent_unless_asked(capfd):
    many([MatchConfig(seed=1, half_time=1.0)], workers=1)
    assert capfd.readouterr().err == ""
