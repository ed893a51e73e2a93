"""The pentanomial SPRT of `arena experiment compare` (experiments/sprt.py) against
numbers published by others: fishtest's LLRs of real Stockfish tests and an OpenBench Elo line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.experiments import sprt

# fishtest's own results lines (normalised Elo bounds), as its database printed them in
# https://github.com/official-stockfish/fishtest/pull/2088: LLR, bounds and Ptnml(0-2).
FISHTEST = [
    ((0.50, 2.50), [61, 12006, 31864, 12078, 47], -2.24),
    ((-1.75, 0.25), [1364, 74663, 161073, 73693, 1479], -0.66),
    ((0.50, 2.50), [57, 4083, 10436, 4259, 56], 1.14),
    ((0.00, 2.00), [129, 5397, 11780, 5428, 98], -1.11),
    ((0.50, 2.50), [33, 1777, 4421, 1801, 29], -0.21),
    ((0.00, 2.00), [0, 236, 690, 265, 0], 0.32),  # two empty cells: regularised
]


@pytest.mark.parametrize("bounds, penta, llr", FISHTEST)
def test_llr_matches_fishtest_published_results(bounds, penta, llr):
    assert round(sprt.llr_normalized(*bounds, penta), 2) == llr


def test_elo_interval_matches_an_openbench_line():
    # https://github.com/Yoshie2000/PlentyChess/pull/226: "Elo 1.42 +- 1.13 (95%)",
    # Penta [846, 13353, 26519, 13740, 878].
    elo, half = sprt.elo_interval([846, 13353, 26519, 13740, 878])
    assert (round(elo, 2), round(half, 2)) == (1.42, 1.13)


def test_the_mle_has_the_t_value_asked_for():
    n, pdf = sprt.distribution([3, 10, 30, 12, 5])
    for t in (-0.2, 0.0, 0.05, 0.3):
        p = sprt.mle_t_value(pdf, 0.5, t)
        mu, var = sprt.mean_var([(a, q) for (a, _), q in zip(pdf, p)])
        assert math.isclose(sum(p), 1.0, abs_tol=1e-9)
        assert math.isclose((mu - 0.5) / math.sqrt(var), t, abs_tol=1e-7)


def test_wald_bounds_and_bad_parameters():
    lower, upper = sprt.Sprt().bounds
    assert (round(lower, 2), round(upper, 2)) == (-2.94, 2.94)
    for bad in ({"elo0": 2, "elo1": 0}, {"alpha": 0}, {"beta": 0.7}, {"elo1": math.inf}):
        with pytest.raises(ValueError):
            sprt.Sprt(**bad)


def test_a_clearly_better_candidate_is_accepted_and_a_worse_one_rejected():
    better, worse = sprt.Sprt(0, 50), sprt.Sprt(0, 50)
    pattern = [1.5, 1.0, 2.0, 1.5, 1.0, 1.5]
    for i in range(200):
        if not better.state:
            better.add(pattern[i % len(pattern)])
        if not worse.state:
            worse.add(2 - pattern[i % len(pattern)])
    assert better.state == "accepted" and worse.state == "rejected"
    assert better.penta[0] == 0 and sum(better.penta) < 100
    line = better.line(3, 1, 2)
    assert line.startswith("Elo ") and "(95%)  LLR " in line and "(-2.94, 2.94) [0.00, 50.00]" in line
    assert line.endswith(f"N: 6 W: 3 L: 1 D: 2  Penta [{', '.join(map(str, better.penta))}]")


@pytest.mark.slow
def test_under_h0_the_test_accepts_at_most_about_alpha():
    """Equal strengths (a symmetric pair distribution): the SPRT accepts "better" in about
    alpha = 5 % of runs or fewer, never in most of them."""
    rng = np.random.default_rng(1)
    probs = [0.05, 0.2, 0.5, 0.2, 0.05]
    accepted = 0
    runs = 100
    for _ in range(runs):
        test = sprt.Sprt(0, 50)
        for score in rng.choice(5, size=300, p=probs) / 2:
            if test.add(score):
                break
        accepted += test.state == "accepted"
    assert accepted <= 0.1 * runs
