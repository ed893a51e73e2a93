"""The one percentile (runtime/stats.py): numpy's linear method, the median at 50."""

import statistics

import numpy as np
import pytest

from arena.runtime.stats import percentile


@pytest.mark.parametrize("n", [1, 2, 5, 100, 101])
def test_percentile_is_numpys_linear_method(n):
    values = list(np.random.default_rng(n).normal(size=n))
    for q in (0, 5, 50, 95, 99, 100):
        assert percentile(values, q) == pytest.approx(float(np.percentile(values, q)), abs=1e-12)
    assert percentile(values, 50) == pytest.approx(statistics.median(values), abs=1e-12)


def test_percentile_of_nothing_is_zero_and_q_is_checked():
    assert percentile([], 95) == 0.0
    with pytest.raises(ValueError):
        percentile([1.0], 101)
