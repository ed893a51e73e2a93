"""SPSA, as fishtest tunes chess engines: perturb every parameter at once, measure twice, step.

Simultaneous perturbation stochastic approximation (Spall 1992, 1998). At
iteration k (0-based), with the standard gain sequences

    c_k = c / (k + 1) ** 0.101            a_k = a / (A + k + 1) ** 0.602

every coordinate of theta is perturbed by +-c_k together (`delta`, a random
sign per coordinate, drawn from the run's seed and k alone, so a resumed run
draws the same), the objective is measured at theta + c_k delta and at
theta - c_k delta (here: the points of a paired set of matches, the same
seeds and ends for both), and theta steps along

    g_k = (y+ - y-) / (2 c_k) * delta        theta <- clip(theta + a_k g_k)

(ascent: the most points). Coordinates live in [0, 1], each parameter's range
mapped linearly (`Space`), so one c and one a serve parameters of any unit; an
int parameter plays the rounded value. Spall's rule of thumb sets A to a tenth
of the iterations.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from arena.strategies.base import Param

ALPHA = 0.602  # Spall's practical exponents (fishtest's too)
GAMMA = 0.101


@dataclass(frozen=True)
class Gains:
    a: float = 0.02  # step size scale, in [0, 1] units per unit of objective per unit of perturbation
    c: float = 0.1  # perturbation, a tenth of each range
    A: float = 0.0  # stability constant: about a tenth of the iterations

    def c_k(self, k: int) -> float:
        return self.c / (k + 1) ** GAMMA

    def a_k(self, k: int) -> float:
        return self.a / (self.A + k + 1) ** ALPHA


def delta(seed: int, k: int, n: int) -> list[int]:
    """The +-1 perturbation of iteration k: from (seed, k) alone, so a resumed run draws the same."""
    rng = random.Random(f"spsa:{seed}:{k}")
    return [1 if rng.random() < 0.5 else -1 for _ in range(n)]


def clip(x: float) -> float:
    return 0.0 if x < 0.0 else 1.0 if x > 1.0 else x


def perturbed(theta: list[float], d: list[int], ck: float) -> tuple[list[float], list[float]]:
    """(theta + c_k delta, theta - c_k delta), each clipped to [0, 1]."""
    return [clip(t + ck * s) for t, s in zip(theta, d)], [clip(t - ck * s) for t, s in zip(theta, d)]


def step(theta: list[float], d: list[int], k: int, y_plus: float, y_minus: float, gains: Gains) -> list[float]:
    """One ascent step from the two measurements of iteration k."""
    ck, ak = gains.c_k(k), gains.a_k(k)
    g = (y_plus - y_minus) / (2.0 * ck)
    return [clip(t + ak * g * s) for t, s in zip(theta, d)]


@dataclass(frozen=True)
class Space:
    """The tuned parameters, each range mapped to [0, 1]."""

    params: tuple[Param, ...]

    def to_unit(self, values: dict) -> list[float]:
        return [(float(values[p.name]) - p.low) / (p.high - p.low) for p in self.params]  # type: ignore[operator]

    def values(self, theta: list[float]) -> dict:
        """theta as parameter values (an int parameter's rounded, every value within its range)."""
        out = {}
        for p, t in zip(self.params, theta):
            v = p.low + clip(t) * (p.high - p.low)  # type: ignore[operator]
            out[p.name] = int(round(v)) if p.type == "int" else round(v, 6)
        return out

    def defaults(self) -> dict:
        return {p.name: p.default for p in self.params}
