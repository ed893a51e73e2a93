"""`arena experiment compare`: is the candidate better than the baseline? Paired matches and
an SPRT (experiments/sprt.py), as chess engines test a change (Stockfish's fishtest).

A pair is one seed played with the ends swapped (team a and its kick-off first for one
side, then for the other):
* without opponents, the candidate plays the baseline: a match is a game, won, drawn or lost
  by the candidate, and the pair scores 0..2;
* with opponents (a list, taken in turn: pair k plays opponent k mod n), the candidate and the
  baseline each play that opponent on the same seed and ends: the candidate wins an end's game
  when its result there beats the baseline's (more points, then a better goal difference),
  draws it when they are equal; the pair scores the two ends' games.

Pairs are counted in the order of their seeds, however many run at once, so a run's verdict
does not depend on --jobs. The test stops when the LLR crosses a bound or at --max-pairs.
Exit codes: 0 accepted (better), 1 rejected (not better), 3 undecided at the maximum.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path

from arena.config import ConfigError, MatchConfig
from arena.experiments.experiment import team_view
from arena.experiments.sprt import Sprt, normalized_elo

EXIT = {"accepted": 0, "rejected": 1, "": 3}
MAX_PAIRS = 100_000


@dataclass
class CompareOptions:
    candidate: str
    baseline: str
    opponents: list[str] = field(default_factory=list)  # empty: the candidate plays the baseline
    elo0: float = 0.0  # fishtest's default bounds for a change: [0, 2] normalised Elo
    elo1: float = 2.0
    alpha: float = 0.05
    beta: float = 0.05
    max_pairs: int = 200
    first_seed: int = 0
    jobs: int = 0
    ray: str | None = None


def matches_of_pair(base: MatchConfig, opts: CompareOptions, k: int) -> list[tuple[tuple, MatchConfig, str]]:
    """[(key, configuration, the side whose result counts)] of pair k: its seed, both ends."""
    seed = opts.first_seed + k
    c, b = opts.candidate, opts.baseline
    if not opts.opponents:
        return [
            ((k, "candidate", "a"), base.replace(seed=seed, home=c, away=b), "a"),
            ((k, "candidate", "b"), base.replace(seed=seed, home=b, away=c), "b"),
        ]
    opp = opts.opponents[k % len(opts.opponents)]
    out = []
    for who, name in (("candidate", c), ("baseline", b)):
        out.append(((k, who, "a"), base.replace(seed=seed, home=name, away=opp), "a"))
        out.append(((k, who, "b"), base.replace(seed=seed, home=opp, away=name), "b"))
    return out


def games_of_pair(opts: CompareOptions, got: dict[tuple, dict], k: int) -> list[float]:
    """The candidate's two games of pair k (1 won, 0.5 drawn, 0 lost), one per end."""
    out = []
    for end in ("a", "b"):
        mine = got[(k, "candidate", end)]
        if not opts.opponents:
            out.append({3: 1.0, 1: 0.5, 0: 0.0}[mine["points"]])
            continue
        theirs = got[(k, "baseline", end)]
        a, b = (mine["points"], mine["goal_diff"]), (theirs["points"], theirs["goal_diff"])
        out.append(1.0 if a > b else 0.5 if a == b else 0.0)
    return out


def check(opts: CompareOptions) -> None:
    if not 1 <= opts.max_pairs <= MAX_PAIRS:
        raise ConfigError(f"--max-pairs must be 1..{MAX_PAIRS}, got {opts.max_pairs}")
    if not 0 <= opts.first_seed < 2**62:
        raise ConfigError(f"--first-seed must be >= 0, got {opts.first_seed}")
    if opts.opponents and opts.candidate == opts.baseline:
        raise ConfigError("with --opponents the candidate and the baseline play the very same matches: name two")
    try:
        Sprt(opts.elo0, opts.elo1, opts.alpha, opts.beta)
    except ValueError as exc:
        raise ConfigError(f"--elo0/--elo1/--alpha/--beta: {exc}") from None


def run(base: MatchConfig, opts: CompareOptions, progress: bool = True, log_dir: Path | None = None) -> dict:
    """Play pairs until the SPRT decides or --max-pairs; the result with its fishtest-style line."""
    import tempfile

    from arena.experiments.executor import Executor

    check(opts)
    test = Sprt(opts.elo0, opts.elo1, opts.alpha, opts.beta)
    wins = losses = draws = 0
    got: dict[tuple, dict] = {}
    pairs: list[dict] = []
    next_pair = counted = 0
    with tempfile.TemporaryDirectory(prefix="arena-compare-") as tmp:
        ex = Executor(opts.jobs, opts.ray, log_dir or Path(tmp))
        with ex:
            while not test.state and counted < opts.max_pairs:
                while next_pair < opts.max_pairs and ex.pending + 2 <= max(ex.capacity, 2):
                    for key, cfg, team in matches_of_pair(base, opts, next_pair):
                        ex.submit((key, team), (cfg, "inprocess", False))
                    next_pair += 1
                for (key, team), played, reason in ex.wait():
                    if played is None:
                        raise RuntimeError(f"pair {key[0]} ({key[1]}, team {key[2]}): {reason}")
                    got[key] = team_view(played, team)
                while counted < next_pair and all(k in got for k, _, _ in matches_of_pair(base, opts, counted)):
                    games = games_of_pair(opts, got, counted)
                    wins += games.count(1.0)
                    losses += games.count(0.0)
                    draws += games.count(0.5)
                    test.add(sum(games))
                    pairs.append({"seed": opts.first_seed + counted, "games": games})
                    counted += 1
                    if progress:
                        print(f"[pair {counted}] {test.line(wins, losses, draws)}", file=sys.stderr, flush=True)
                    if test.state:
                        break
            ex.abandon()
    verdict = {
        "accepted": f"H1 accepted: {opts.candidate} is better than {opts.baseline} (nElo >= {opts.elo1:g})",
        "rejected": f"H0 accepted: {opts.candidate} is not better than {opts.baseline} (nElo <= {opts.elo0:g})",
        "": f"undecided after {counted} pairs (--max-pairs {opts.max_pairs})",
    }[test.state]
    return {
        "candidate": opts.candidate,
        "baseline": opts.baseline,
        "opponents": opts.opponents,
        "line": test.line(wins, losses, draws),
        "verdict": verdict,
        "state": test.state or "undecided",
        "exit": EXIT[test.state],
        "llr": round(test.llr, 4),
        "bounds": [round(x, 4) for x in test.bounds],
        "elo0": opts.elo0,
        "elo1": opts.elo1,
        "nelo": round(normalized_elo(test.penta), 3),
        "pairs": len(pairs),
        "W": wins,
        "L": losses,
        "D": draws,
        "penta": test.penta,
        "per_pair": pairs,
    }
