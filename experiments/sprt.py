"""Pentanomial statistics and the sequential probability ratio test of `arena experiment compare`.

Implemented from the formulas of Stockfish's fishtest (server/fishtest/stats/LLRcalc.py,
sprt.py and stat_util.py, https://github.com/official-stockfish/fishtest) and the notes
they cite (M. Van den Bergh, "Normalized Elo: practical considerations",
https://www.cantate.be/Fishtest/normalized_elo_practical.pdf, section 4.1; "Support of the
MLE for a multinomial", support_MLE_multinomial.pdf, Proposition 1.1):

* A pair (the same seed, the ends swapped) scores 0, 1/2, 1, 3/2 or 2 for the candidate; the
  pentanomial counts how many pairs scored each. A count of zero is replaced by 1e-3 (the
  regularisation), and the empirical distribution has values a_i = i/4, i = 0..4, per pair.
* Normalised Elo: nElo = (mu - 1/2) / sigma * 800 / ln 10, with mu the mean score per match
  and sigma its standard deviation per match (sqrt(2) times the per-pair standard deviation
  of the pair's mean). Its t-value per pair is t = sqrt(2) * nElo / (800 / ln 10).
* The generalised log-likelihood ratio of H1 (t = t1) against H0 (t = t0) is
  N * sum_i phat_i * (ln p1_i - ln p0_i), where p_j is the maximum-likelihood distribution on
  the same values whose t-value (mu - 1/2) / sigma is t_j. It is found by a fixed-point
  iteration: with mu, sigma of the current p, the values
  a'_i = a_i - 1/2 - t * sigma * (1 + ((mu - a_i) / sigma)^2) / 2 define
  p_i = phat_i / (1 + x a'_i), x the root of the secular equation sum_i phat_i a'_i / (1 + x a'_i) = 0.
* Wald's bounds: ln(beta / (1 - alpha)) and ln((1 - beta) / alpha), -2.94 and 2.94 for 0.05, with
  fishtest's dynamic overshoot correction (Siegmund, Sequential Analysis, Corollary 8.33).
* Elo ± its 95 % interval as fishtest prints it (stat_util.get_elo): the logistic Elo of the mean
  score per match, the interval from the normal approximation of the mean with the pentanomial variance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from statistics import NormalDist

NELO_PER_NT = 800 / math.log(10)  # normalised Elo per unit of t-value (per match)
REGULARISE = 1e-3  # a pentanomial count of 0 counts this much


def regularised(counts: list[float]) -> list[float]:
    return [c if c > 0 else REGULARISE for c in counts]


def distribution(counts: list[float]) -> tuple[float, list[tuple[float, float]]]:
    """(N, [(value, probability)]) of trinomial or pentanomial counts, values evenly in [0, 1]."""
    counts = regularised(counts)
    n = sum(counts)
    last = len(counts) - 1
    return n, [(i / last, c / n) for i, c in enumerate(counts)]


def mean_var(pdf: list[tuple[float, float]]) -> tuple[float, float]:
    mu = sum(p * a for a, p in pdf)
    return mu, sum(p * (a - mu) ** 2 for a, p in pdf)


def _secular(pdf: list[tuple[float, float]]) -> float:
    """The root x of sum p_i a_i / (1 + x a_i) = 0 between -1/max(a) and -1/min(a) (needs min < 0 < max).
    The sum falls strictly with x there, so bisection finds it."""
    lo_a, hi_a = min(a for a, _ in pdf), max(a for a, _ in pdf)
    if not lo_a < 0 < hi_a:
        raise ValueError("the secular equation needs values on both sides of 0")
    lo, hi = -1 / hi_a, -1 / lo_a
    span = hi - lo
    lo, hi = lo + 1e-12 * span, hi - 1e-12 * span

    def f(x: float) -> float:
        return sum(p * a / (1 + x * a) for a, p in pdf)

    for _ in range(200):
        mid = (lo + hi) / 2
        if f(mid) > 0:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-15 * max(1.0, abs(mid)):
            break
    return (lo + hi) / 2


def mle_t_value(pdf: list[tuple[float, float]], ref: float, t: float) -> list[float]:
    """The maximum-likelihood probabilities on `pdf`'s values whose (mu - ref) / sigma is `t`."""
    values = [a for a, _ in pdf]
    probs = [1 / len(pdf)] * len(pdf)  # start from the uniform distribution
    for _ in range(100):
        mu, var = mean_var(list(zip(values, probs)))
        sigma = math.sqrt(var)
        shifted = [a - ref - t * sigma * (1 + ((mu - a) / sigma) ** 2) / 2 for a in values]
        x = _secular([(s, p) for s, (_, p) in zip(shifted, pdf)])
        new = [p / (1 + x * s) for s, (_, p) in zip(shifted, pdf)]
        if max(abs(a - b) for a, b in zip(new, probs)) < 1e-12:
            return new
        probs = new
    return probs


def llr_normalized(nelo0: float, nelo1: float, counts: list[float]) -> float:
    """The generalised LLR of nElo = nelo1 against nElo = nelo0 for trinomial (L, D, W) or
    pentanomial counts (fishtest's LLR_normalized)."""
    n, pdf = distribution(counts)
    scale = math.sqrt(2) if len(counts) == 5 else 1.0
    t0, t1 = (nelo / NELO_PER_NT * scale for nelo in (nelo0, nelo1))
    p0, p1 = mle_t_value(pdf, 0.5, t0), mle_t_value(pdf, 0.5, t1)
    return n * sum(ph * (math.log(b) - math.log(a)) for (_, ph), a, b in zip(pdf, p0, p1))


def elo_interval(counts: list[float], level: float = 0.95) -> tuple[float, float]:
    """(Elo, half-width of its `level` interval) from pentanomial counts, as fishtest prints them."""
    counts = regularised(counts)
    last = len(counts) - 1
    games = sum(counts) * last / 2
    mu = sum(c * i / 2 for i, c in enumerate(counts)) / games
    mu_pair = last / 2 * mu
    var = sum(c * (i / 2 - mu_pair) ** 2 for i, c in enumerate(counts)) / games
    z = NormalDist().inv_cdf(0.5 + level / 2)
    half = z * math.sqrt(var / games)
    return _elo(mu), (_elo(mu + half) - _elo(mu - half)) / 2


def normalized_elo(counts: list[float]) -> float:
    n, pdf = distribution(counts)
    mu, var = mean_var(pdf)
    sigma_match = math.sqrt(2 * var) if len(counts) == 5 else math.sqrt(var)
    return (mu - 0.5) / sigma_match * NELO_PER_NT


def _elo(score: float) -> float:
    score = min(max(score, 1e-3), 1 - 1e-3)
    return -400 * math.log10(1 / score - 1)


@dataclass
class Sprt:
    """An SPRT between normalised Elo bounds, updated one pair at a time (fishtest's update_SPRT)."""

    elo0: float = 0.0
    elo1: float = 2.0
    alpha: float = 0.05
    beta: float = 0.05
    penta: list[int] = field(default_factory=lambda: [0] * 5)
    llr: float = 0.0
    state: str = ""  # "", "accepted" (H1: better) or "rejected" (H0)
    # overshoot: the running minimum (ref0) and maximum (ref1) of the LLR and the sums of the jumps past them
    _ref0: float = 0.0
    _m0: float = 0.0
    _sq0: float = 0.0
    _ref1: float = 0.0
    _m1: float = 0.0
    _sq1: float = 0.0

    def __post_init__(self) -> None:
        if not (0 < self.alpha < 0.5 and 0 < self.beta < 0.5):
            raise ValueError(f"alpha and beta must be in (0, 0.5), got {self.alpha} and {self.beta}")
        if not (math.isfinite(self.elo0) and math.isfinite(self.elo1) and self.elo0 < self.elo1):
            raise ValueError(f"give finite Elo bounds elo0 < elo1, got {self.elo0} and {self.elo1}")

    @property
    def bounds(self) -> tuple[float, float]:
        return math.log(self.beta / (1 - self.alpha)), math.log((1 - self.beta) / self.alpha)

    def add(self, pair_score: float) -> str:
        """Count one pair (0, 0.5, 1, 1.5 or 2 for the candidate) and test; returns the state."""
        self.penta[round(2 * pair_score)] += 1
        self.llr = llr_normalized(self.elo0, self.elo1, self.penta)
        if self.llr < self._ref0:
            d = self.llr - self._ref0
            self._m0, self._sq0, self._ref0 = self._m0 + d, self._sq0 + d * d, self.llr
        if self.llr > self._ref1:
            d = self.llr - self._ref1
            self._m1, self._sq1, self._ref1 = self._m1 + d, self._sq1 + d * d, self.llr
        o0 = -self._sq0 / self._m0 / 2 if self._m0 else 0.0
        o1 = self._sq1 / self._m1 / 2 if self._m1 else 0.0
        lower, upper = self.bounds
        self.state = "rejected" if self.llr < lower + o0 else "accepted" if self.llr > upper - o1 else ""
        return self.state

    def line(self, wins: int, losses: int, draws: int) -> str:
        """`Elo 12.34 ± 5.67 (95%)  LLR 2.95 (-2.94, 2.94) [0.00, 2.00]  N: 40 W: 20 L: 10 D: 10  Penta [...]`."""
        elo, half = elo_interval(self.penta)
        lower, upper = self.bounds
        return (
            f"Elo {elo:.2f} ± {half:.2f} (95%)  LLR {self.llr:.2f} ({lower:.2f}, {upper:.2f}) "
            f"[{self.elo0:.2f}, {self.elo1:.2f}]  N: {wins + losses + draws} W: {wins} L: {losses} D: {draws}  "
            f"Penta [{', '.join(map(str, self.penta))}]"
        )
