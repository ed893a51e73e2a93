"""Order statistics, defined once for every report (tick timing, link delays, reviews)."""

from __future__ import annotations

from collections.abc import Iterable


def percentile(values: Iterable[float], q: float) -> float:
    """The q-th percentile (q in [0, 100]) of `values`, 0.0 if there are none.

    Linear interpolation between the two nearest ranks (numpy's default
    method), so `percentile(v, 50)` is the median.
    """
    s = sorted(values)
    if not s:
        return 0.0
    if not 0.0 <= q <= 100.0:
        raise ValueError(f"percentile {q} is not in [0, 100]")
    pos = (len(s) - 1) * q / 100.0
    lo = int(pos)
    hi = min(lo + 1, len(s) - 1)
    return s[lo] + (s[hi] - s[lo]) * (pos - lo)
