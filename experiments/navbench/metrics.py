"""What a trial counts as: safe, collision-free, average iterations, median times, paper 1's ordering."""

from __future__ import annotations

import statistics
from collections.abc import Iterable

from arena.experiments.navbench.spec import ORDER
from arena.experiments.navbench.trials import Trial


def _median_us(ns: Iterable[int]) -> float | None:
    values = list(ns)
    return round(statistics.median(values) / 1000.0, 3) if values else None


def _avg_iterations(trials: list[Trial]) -> float | None:
    done = [t.iterations for t in trials if t.reached]
    return round(sum(done) / len(done), 1) if done else None


def _safe(t: Trial) -> bool:
    """Safe navigation: the target reached without touching an obstacle.

    Paper 1 uses "free collision" and "safe navigation" as synonyms, and all of
    its trials reach the target. Here a trial can also run out of time, so
    "safe" asks for both; the collision-free count alone is reported too.
    """
    return t.reached and t.collisions == 0


def _free(t: Trial) -> bool:
    return t.collisions == 0


def _ordered(rates: dict[str, float]) -> bool | None:
    """Paper 1's claim F-SFM >= SFM >= APF over the methods present (None with fewer than two)."""
    order = [m for m in ORDER if m in rates]
    return all(rates[a] >= rates[b] for a, b in zip(order, order[1:])) if len(order) > 1 else None
