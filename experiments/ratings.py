"""A tournament's standings: the paper's Table 2, per-robot coverage (Fig. 9) and
Bradley-Terry ratings with bootstrap confidence intervals; the Wilson interval of a pass rate."""

from __future__ import annotations

import math
import random
from dataclasses import replace

from arena.experiments.fixtures import Result, plural, short

Z95 = 1.959963984540054  # the standard normal's 97.5 % quantile


def wilson(passed: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a pass rate `passed / n` (95 % by default): a scenario's pass rate,
    an experiment's `pass` per cell."""
    if n == 0:
        return 0.0, 1.0
    p = passed / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def standings(results: list[Result], teams: list[str]) -> list[dict]:
    """Table 2: W D L GF GA GD P per team, ranked by P, then GD, then GF."""
    rows = {t: {"team": t, "W": 0, "D": 0, "L": 0, "GF": 0, "GA": 0} for t in teams}
    for r in results:
        if r.status != "ok":
            continue
        for team in (r.home, r.away):
            gf, ga = r.goals(team)
            row = rows[team]
            row["GF"] += gf
            row["GA"] += ga
            row["W" if gf > ga else "D" if gf == ga else "L"] += 1
    for row in rows.values():
        row["GD"] = row["GF"] - row["GA"]
        row["P"] = 3 * row["W"] + row["D"]
    return sorted(rows.values(), key=lambda r: (-r["P"], -r["GD"], -r["GF"], r["team"]))


def coverage(results: list[Result], teams: list[str]) -> dict[str, dict]:
    """Fig. 9: mean distance of robot 1 and robot 2 per match, and their ratio."""
    out = {}
    for t in teams:
        d1 = [
            d
            for r in results
            if r.status == "ok" and t in (r.home, r.away) and (d := r.robot_distance(t, 1)) is not None
        ]
        d2 = [
            d
            for r in results
            if r.status == "ok" and t in (r.home, r.away) and (d := r.robot_distance(t, 2)) is not None
        ]
        m1 = sum(d1) / len(d1) if d1 else 0.0
        m2 = sum(d2) / len(d2) if d2 else 0.0
        out[t] = {"robot1_m": round(m1, 2), "robot2_m": round(m2, 2), "ratio": round(m1 / m2, 3) if m2 > 0 else None}
    return out


def bradley_terry(results: list[Result], teams: list[str], iters: int = 200) -> dict[str, float]:
    """Bradley-Terry strengths by the MM algorithm; a draw counts half a win each way.

    One virtual draw between every pair keeps a team that won everything finite.
    Returned on an Elo-like scale: 1500 + 400 log10(strength / geometric mean).
    """
    wins = {(i, j): 0.5 for i in teams for j in teams if i != j}  # the virtual draw
    for r in results:
        if r.status != "ok":
            continue
        h, a = r.score
        if h > a:
            wins[(r.home, r.away)] += 1
        elif a > h:
            wins[(r.away, r.home)] += 1
        else:
            wins[(r.home, r.away)] += 0.5
            wins[(r.away, r.home)] += 0.5
    p = dict.fromkeys(teams, 1.0)
    for _ in range(iters):
        new = {}
        for i in teams:
            w_i = sum(wins[(i, j)] for j in teams if j != i)
            denom = sum((wins[(i, j)] + wins[(j, i)]) / (p[i] + p[j]) for j in teams if j != i)
            new[i] = w_i / denom if denom > 0 else p[i]
        g = math.exp(sum(math.log(v) for v in new.values()) / len(new))
        p = {k: v / g for k, v in new.items()}
    return {t: 1500.0 + 400.0 * math.log10(p[t]) for t in teams}


def replay_odds(p: float, draw_rate: float) -> tuple[float, float, float]:
    """P(win), P(draw), P(loss) of a replayed fixture whose Bradley-Terry p is `p`.

    A draw counts half a win, as in the fit, so P(win) + P(draw)/2 = p.
    """
    d = min(draw_rate, 2.0 * min(p, 1.0 - p))
    return p - d / 2, d, 1.0 - p - d / 2


def ratings(results: list[Result], teams: list[str], boot: int = 400, seed: int = 0) -> tuple[list[dict], list[str]]:
    """Ratings with 95 % intervals from a parametric bootstrap, and plain-language notes.

    Each bootstrap replays every played fixture with an outcome drawn from the
    fitted model and refits. Unlike resampling the matches, this stays honest
    for a handful of matches: one 1-0 win does not make a team certain. In the
    model a draw counts half a win, as in the fit, so a fixture's expected
    score is the Bradley-Terry p = s_home / (s_home + s_away): draws come at
    the observed draw rate d, capped at 2 min(p, 1 - p), and take d/2 from
    each side's p. (Drawing them at the plain rate d from every fixture pulled
    a weak team's replayed score up, to 0.8 p + 0.1 with 20 % draws: its whole
    interval then lay above its rating.)
    """
    ok = [r for r in results if r.status == "ok"]
    if not any(r.score[0] != r.score[1] for r in ok):
        # Draws alone (or nothing played) fit every team at 1500 with a zero-width interval: that reads as
        # certainty that they are equal, from what is no evidence at all.
        rows = [{"team": t, "rating": None, "ci95": None} for t in sorted(teams)]
        why = (
            "no match was played"
            if not ok
            else ("the one played match was a draw" if len(ok) == 1 else f"all {len(ok)} played matches were draws")
        )
        return rows, [f"no ratings yet: {why}, so nothing tells the strategies apart; play more legs."]
    point = bradley_terry(ok, teams)
    strength = {t: 10 ** ((v - 1500.0) / 400.0) for t, v in point.items()}
    draw_rate = sum(1 for r in ok if r.score[0] == r.score[1]) / len(ok) if ok else 0.0
    rng = random.Random(seed)
    samples: dict[str, list[float]] = {t: [] for t in teams}
    for _ in range(boot if ok else 0):
        replay = []
        for r in ok:
            u = rng.random()
            win, draw, _ = replay_odds(strength[r.home] / (strength[r.home] + strength[r.away]), draw_rate)
            score = [1, 0] if u < win else [0, 0] if u < win + draw else [0, 1]
            replay.append(replace(r, score=score))  # only the score differs (asdict's deep copy was 3/4 of this)
        for t, v in bradley_terry(replay, teams, iters=60).items():
            samples[t].append(v)
    rows = []
    for t in sorted(teams, key=lambda t: -point[t]):
        s = sorted(samples[t]) or [point[t]]
        lo, hi = s[int(0.025 * (len(s) - 1))], s[int(0.975 * (len(s) - 1))]
        rows.append({"team": t, "rating": round(point[t], 1), "ci95": [round(lo, 1), round(hi, 1)]})
    notes = []
    for upper, lower in zip(rows, rows[1:]):
        if upper["ci95"][0] <= lower["ci95"][1]:
            n = sum(1 for r in ok if {r.home, r.away} == {upper["team"], lower["team"]})
            notes.append(
                f"{short(upper['team'])} and {short(lower['team'])} cannot be told apart: their 95 % intervals "
                f"overlap ({plural(n, 'direct match', 'direct matches')}); more legs are needed to separate them."
            )
    return rows, notes
