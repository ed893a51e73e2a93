"""`arena tournament`: round-robins of strategies, with the paper's tables and statistics.

Every pairing of the strategies plays `legs` matches, alternating home and
away, each with a seed derived from the tournament seed. Every match is a full,
isolated `arena match` process group; `--jobs` of them run at once. Each
result is written atomically to `<out>/matches/<id>.json` as soon as it is in,
so `--resume` skips what is done, Ctrl-C keeps it, and a crashed match (retried
once) is recorded as failed with its reason instead of corrupting the tables.

Outputs in `--out` (Markdown, CSV, JSON, PNG): the paper's Table 1 (scores per
pairing and leg), Table 2 (W, D, L, GF, GA, GD, P; 3/1/0 points; ranked by
points, then goal difference, then goals for), per-robot coverage distance with
the robot 1 / robot 2 ratio (paper's Fig. 9), a goal-difference chart (Fig. 8),
and Bradley-Terry ratings with bootstrap confidence intervals.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import random
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import asdict, dataclass, field
from itertools import combinations
from pathlib import Path

from arena.runtime import seeds
from arena.tools.experiments import pools

ABBREV = {"advance-dynamic": "AD", "advance-static": "AS", "basic-dynamic": "BD", "basic-static": "BS"}


def plural(n: int, word: str, words: str | None = None) -> str:
    """`1 leg`, `2 legs`, `1 match`, `3 matches`."""
    return f"{n} {word if n == 1 else (words or word + 's')}"


# Settings that decide what a match is: --resume refuses to mix results played with other values.
BINDING = ("strategies", "legs", "half_time", "robots", "link", "link_overrides", "perception_latency", "seed")
# What a settings.json written before a binding setting existed was played with.
LEGACY = {"perception_latency": 0}


@dataclass(frozen=True)
class TournamentOptions:
    """What `arena tournament` plays and how: its flags, typed (arena/commands/tournament.py builds one from argv)."""

    strategies: tuple[str, ...]  # resolved names, in the order given
    legs: int = 10
    half_time: float = 300.0  # [s] simulated, per half
    robots: int = 3
    link: str = "ideal"
    link_param: tuple[str, ...] = ()  # CLASS.PARAM=V, as given to --link-param
    perception_latency: int | None = None  # [ticks] None: the default (runtime/config.py DEFAULT_PERCEPTION_LATENCY)
    seed: int = 0
    jobs: int = 0  # 0: one per core
    out: Path = Path("tournament")
    resume: bool = False
    json: bool = False
    engine: str = "processes"
    ray: str | None = None  # None: no Ray; "": a local instance; else auto or HOST:PORT
    ray_runtime_env: str | None = None  # JSON text

    def latency(self) -> int:
        """The perception latency the matches are played with [ticks]."""
        from arena.runtime.config import DEFAULT_PERCEPTION_LATENCY

        return DEFAULT_PERCEPTION_LATENCY if self.perception_latency is None else self.perception_latency

    def link_overrides(self) -> dict[str, dict[str, float]]:
        from arena.runtime.links import parse_override

        overrides: dict[str, dict[str, float]] = {}
        for text in self.link_param:
            cls, param, value = parse_override(text)
            overrides.setdefault(cls, {})[param] = value
        return overrides


def settings(opts: TournamentOptions) -> dict:
    """Everything needed to play the tournament again (tournament.json, report.md, --resume's check)."""
    from arena.runtime.version import package_version

    return {
        "strategies": list(opts.strategies),
        "legs": opts.legs,
        "half_time": float(opts.half_time),
        "robots": opts.robots,
        "link": opts.link,
        "link_overrides": opts.link_overrides(),
        "perception_latency": opts.latency(),
        "seed": opts.seed,
        "engine": opts.engine,
        "version": package_version(),
    }


def check_resume(out: Path, now: dict) -> None:
    """ConfigError naming every setting that differs from the ones `out` was played with."""
    from arena.runtime.config import ConfigError

    if not (out / "settings.json").exists() and not (out / "matches").is_dir():
        # Starting the whole tournament from nothing is what a mistyped --out would do without a word.
        what = "does not exist" if not out.exists() else "holds no tournament"
        raise ConfigError(f"--resume: {out} {what}, so there is nothing to resume (leave out --resume to start one)")
    path = out / "settings.json"
    if not path.exists():
        return  # an older tournament directory: nothing recorded to compare
    try:
        before = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ConfigError(f"--resume: cannot read {path}: {exc}") from None
    flag = {"link_overrides": "link-param", "half_time": "half-time", "perception_latency": "perception-latency"}
    diffs = [
        f"--{flag.get(k, k)} {_show(before.get(k, LEGACY.get(k)))} there, {_show(now[k])} now"
        for k in BINDING
        if before.get(k, LEGACY.get(k)) != now[k]
    ]
    if diffs:
        raise ConfigError(
            f"--resume: {out} was played with different settings: {'; '.join(diffs)} "
            "(give the same settings, or another --out)"
        )


def _show(value) -> str:
    if isinstance(value, list):
        return ",".join(short(v) for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, dict):
        return ",".join(f"{c}.{p}={v:g}" for c, ps in sorted(value.items()) for p, v in sorted(ps.items())) or "none"
    return str(value)


def short(name: str) -> str:
    return ABBREV.get(name, name)


def file_safe(name: str) -> str:
    """`short(name)` fit for a file name: a policy file's strategy by its prefix and file name."""
    kind, _, path = short(name).partition(":")
    return f"{kind}-{os.path.basename(path)}" if path else kind.replace("/", "-")


# ------------------------------------------------------------------ schedule
@dataclass(frozen=True)
class Fixture:
    index: int  # position in the schedule
    first: str  # pairing as listed (the column order of Table 1)
    second: str
    leg: int  # 1-based
    home: str
    away: str
    seed: int

    @property
    def id(self) -> str:
        """The match's file name stem: a name such as `policy:/runs/p.pkl` as `policy-p.pkl`."""
        return f"{self.index:03d}-{file_safe(self.first)}-{file_safe(self.second)}-leg{self.leg:02d}"


def schedule(strategies: list[str], legs: int, seed: int) -> list[Fixture]:
    """Every pairing `legs` times, home and away alternating, seeds from the tournament seed."""
    out: list[Fixture] = []
    for first, second in combinations(strategies, 2):
        for leg in range(1, legs + 1):
            home, away = (first, second) if leg % 2 == 1 else (second, first)
            match_seed = seeds.derive(seed, "tournament", first, second, leg) % (2**31)
            out.append(Fixture(len(out), first, second, leg, home, away, match_seed))
    return out


# ------------------------------------------------------------------- results
def fixture_fields(fx: Fixture) -> dict:
    """The fields a `Result` repeats from its fixture."""
    return {k: getattr(fx, k) for k in ("first", "second", "leg", "home", "away", "seed")}


@dataclass
class Result:
    id: str
    first: str
    second: str
    leg: int
    home: str
    away: str
    seed: int
    status: str  # "ok" or "failed"
    score: list[int] = field(default_factory=lambda: [0, 0])  # [home, away]
    distance_m: dict[str, float] = field(default_factory=dict)  # "a/1" -> m
    reason: str = ""
    attempts: int = 0
    wall_seconds: float = 0.0
    rtf: float = 0.0
    digest: str = ""
    engine: str = "processes"  # which engine played it (arena match --engine)
    faults: list[dict] = field(
        default_factory=list
    )  # a team's crashed process: the match counts (tools/launch/faults.py)

    @classmethod
    def played(cls, fx: Fixture, m: dict, attempts: int, wall_seconds: float, engine: str) -> Result:
        """Fixture `fx`'s result from its match JSON `m` (one that `void_reason` accepted)."""
        return cls(
            id=fx.id,
            status="ok",
            score=m["score"],
            distance_m=m["distance_m"],
            attempts=attempts,
            wall_seconds=round(wall_seconds, 2),
            rtf=m["rtf"],
            digest=m["digest"],
            engine=engine,
            faults=m.get("faults", []),
            **fixture_fields(fx),
        )

    @classmethod
    def failed(cls, fx: Fixture, reason: str, attempts: int, engine: str) -> Result:
        return cls(id=fx.id, status="failed", reason=reason, attempts=attempts, engine=engine, **fixture_fields(fx))

    def goals(self, team: str) -> tuple[int, int]:
        """(for, against) for `team` in this match."""
        h, a = self.score
        return (h, a) if team == self.home else (a, h)

    def robot_distance(self, team: str, n: int) -> float | None:
        side = "a" if team == self.home else "b"
        return self.distance_m.get(f"{side}/{n}")


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def load_results(directory: Path) -> dict[str, Result]:
    out: dict[str, Result] = {}
    if not directory.is_dir():
        return out
    for f in sorted(directory.glob("*.json")):
        try:
            r = Result(**json.loads(f.read_text()))
        except (ValueError, TypeError):
            continue  # a torn or foreign file: the match is simply played again
        out[r.id] = r
    return out


# --------------------------------------------------------------------- tables
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
        why = "no match was played" if not ok else f"all {plural(len(ok), 'played match', 'played matches')} were draws"
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
            replay.append(Result(**{**asdict(r), "score": score}))
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


# --------------------------------------------------------------------- output
def table1_rows(results: list[Result], strategies: list[str], legs: int) -> tuple[list[str], list[list[str]]]:
    pairs = list(combinations(strategies, 2))
    header = ["leg"] + [f"{short(a)} vs {short(b)}" for a, b in pairs]
    by_key = {(r.first, r.second, r.leg): r for r in results}
    rows = []
    for leg in range(1, legs + 1):
        row = [str(leg)]
        for a, b in pairs:
            r = by_key.get((a, b, leg))
            if r is None:
                row.append("")
            elif r.status != "ok":
                row.append("failed")
            else:
                row.append(f"{r.goals(a)[0]}-{r.goals(b)[0]}")
        rows.append(row)
    return header, rows


def markdown(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def csv_text(header: list[str], rows: list[list]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue()


def charts(out: Path, table: list[dict], cover: dict[str, dict]) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    written = []
    teams = [r["team"] for r in table]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    gd = [r["GD"] for r in table]
    bars = ax.bar([short(t) for t in teams], gd, color=["tab:green" if g >= 0 else "tab:red" for g in gd])
    ax.bar_label(bars, labels=[f"{g:+d}" if g else "0" for g in gd], padding=2)  # a 0 is said, not left blank
    ax.axhline(0, color="black", linewidth=0.8)
    top = max(1, *(abs(g) for g in gd)) * 1.25  # whole goals: never a +-0.04 axis when every GD is 0
    ax.set_ylim(-top, top)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("goal difference")
    ax.set_title("Goal difference per strategy (paper Fig. 8)" + ("" if any(gd) else ": all level"))
    fig.tight_layout()
    fig.savefig(out / "goal_difference.png", dpi=120)
    plt.close(fig)
    written.append(out / "goal_difference.png")

    fig, ax = plt.subplots(figsize=(6, 3.5))
    xs = range(len(teams))
    ax.bar([x - 0.2 for x in xs], [cover[t]["robot1_m"] for t in teams], width=0.4, label="robot 1")
    ax.bar([x + 0.2 for x in xs], [cover[t]["robot2_m"] for t in teams], width=0.4, label="robot 2")
    for x, t in zip(xs, teams):
        ratio = cover[t]["ratio"]
        if ratio is not None:
            ax.annotate(f"{ratio:.2f}", (x, max(cover[t]["robot1_m"], cover[t]["robot2_m"])), ha="center", va="bottom")
    ax.set_xticks(list(xs), [short(t) for t in teams])
    ax.set_ylabel("mean distance per match [m]")
    ax.margins(y=0.15)
    ax.set_title("Coverage of robot 1 and robot 2, with ratio (paper Fig. 9)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, frameon=False)  # below: never over a label
    fig.tight_layout()
    fig.savefig(out / "coverage.png", dpi=120)
    plt.close(fig)
    written.append(out / "coverage.png")
    return written


def report(
    results: list[Result],
    strategies: list[str],
    legs: int,
    out: Path,
    wall: float,
    seed: int,
    engine: str = "processes",
    total: int | None = None,
    setup: dict | None = None,
) -> dict:
    """Write every table and chart to `out`; return the JSON summary. `engine`: which one played.

    `total`: the matches the schedule has (more than `results` when interrupted);
    `setup`: the tournament's settings (`settings()`), recorded in both outputs.
    """
    total = len(results) if total is None else total
    setup = setup or {"strategies": strategies, "legs": legs, "seed": seed, "engine": engine}
    done = [r for r in results if r.status == "ok"]
    table = standings(results, strategies)
    cover = coverage(results, strategies)
    rates, notes = ratings(results, strategies, seed=seed)
    failed = [{"id": r.id, "reason": r.reason} for r in results if r.status != "ok"]
    faulty = [{"id": r.id, **f} for r in results if r.status == "ok" for f in r.faults]

    h1, rows1 = table1_rows(results, strategies, legs)
    cols2 = ["team", "W", "D", "L", "GF", "GA", "GD", "P"]
    rows2 = [[short(r["team"])] + [r[c] for c in cols2[1:]] for r in table]
    cols3 = ["team", "robot1_m", "robot2_m", "ratio"]
    rows3 = [[short(t)] + [cover[t][c] for c in cols3[1:]] for t in strategies]
    rows4 = [[short(r["team"]), *(["", "", ""] if r["rating"] is None else [r["rating"], *r["ci95"]])] for r in rates]
    cols4 = ["team", "rating", "ci95_low", "ci95_high"]
    for name, head, rows in (
        ("table1", h1, rows1),
        ("table2", cols2, rows2),
        ("coverage", cols3, rows3),
        ("ratings", cols4, rows4),
    ):
        write_atomic(out / f"{name}.csv", csv_text(head, rows))
    md = [
        f"# Tournament: {', '.join(short(s) for s in strategies)}, {plural(legs, 'leg')}, seed {seed}",
        "",
        f"{len(done)} of {plural(total, 'match', 'matches')} played ({len(failed)} failed), "
        f"{wall:.0f} s of wall time, engine {engine} (arena tournament --engine).",
        "",
        "Settings: " + ", ".join(f"{k.replace('_', ' ')} {_show(v)}" for k, v in setup.items()) + ".",
        "",
        "## Table 1: scores per pairing and leg (first-named team's goals first)",
        "",
        markdown(h1, rows1),
        "## Table 2: standings (3 points a win, 1 a draw; ranked by P, GD, GF)",
        "",
        markdown(cols2, rows2),
        "## Coverage: mean distance per match of robot 1 and robot 2 (paper Fig. 9)",
        "",
        markdown(cols3, rows3),
        "## Ratings: Bradley-Terry, 95 % bootstrap intervals",
        "",
        markdown(cols4, rows4),
    ]
    if notes:
        md += ["Notes:", ""] + [f"- {n}" for n in notes] + [""]
    if failed:
        md += ["## Failed matches", ""] + [f"- {f['id']}: {f['reason']}" for f in failed] + [""]
    if faulty:
        md += ["## Matches played with faults (they count: a team's crash is the team's own)", ""]
        md += [f"- {f['id']}: {f['process']} at tick {f['tick']}: {f['reason']}" for f in faulty] + [""]
    if done:
        charts(out, table, cover)
        md += ["![goal difference](goal_difference.png)", "", "![coverage](coverage.png)", ""]
    write_atomic(out / "report.md", "\n".join(md))
    summary = {
        "strategies": strategies,
        "legs": legs,
        "seed": seed,
        "settings": setup,
        "played": len(done),
        "scheduled": total,
        "table": table,
        "coverage_ratio": {t: cover[t]["ratio"] for t in strategies},
        "coverage": cover,
        "ratings": rates,
        "notes": notes,
        "matches": [asdict(r) for r in results],
        "failed": failed,
        "faults": faulty,
        "wall_seconds": round(wall, 2),
        "engine": engine,
        "out": str(out),
    }
    write_atomic(out / "tournament.json", json.dumps(summary, indent=2))
    return summary


def void_reason(m: dict) -> str:
    """Why a match's JSON is no result ("" if it is one): a void match never counts (tools/launch/faults.py)."""
    if m.get("outcome") == "void" or m.get("void"):
        return "void: " + "; ".join(m.get("outcome_reasons") or ["no reason given"])
    return ""


# ----------------------------------------------------------------------- run
class Runner:
    """Plays fixtures as `arena match` subprocesses; stoppable from the main thread."""

    def __init__(self, opts: TournamentOptions, out: Path):
        self.opts = opts
        self.matches_dir = out / "matches"
        self.matches_dir.mkdir(parents=True, exist_ok=True)
        self.logs_dir = out / "logs"
        self.logs_dir.mkdir(exist_ok=True)
        self._lock = threading.Lock()
        self._running: set[subprocess.Popen] = set()
        self.stopping = False
        self.engine = opts.engine
        # --engine inprocess: one worker process per job, each playing whole
        # matches in one thread, one after another; it imports once, not per match.
        self.pool = None
        if self.engine == "inprocess":
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            self.pool = ProcessPoolExecutor(
                max_workers=opts.jobs or default_jobs(),
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_worker_init,
            )

    def match_config(self, fx: Fixture):
        from arena.runtime.config import MatchConfig, TimingParams

        cfg = MatchConfig(
            seed=fx.seed,
            home=fx.home,
            away=fx.away,
            robots=self.opts.robots,
            half_time=self.opts.half_time,
            link=self.opts.link,
            link_overrides=self.opts.link_overrides(),
            timing=TimingParams(perception_latency=self.opts.latency()),
        )
        cfg.validate()
        return cfg

    def play_inprocess(self, fx: Fixture) -> Result | None:
        """`play` on a worker process of the pool (--engine inprocess)."""
        reason = ""
        for attempt in (1, 2):
            if self.stopping:
                return None
            t0 = time.monotonic()
            try:
                m = self.pool.submit(_play_inprocess, self.match_config(fx)).result()
            except Exception as exc:  # a failed match is recorded, never fatal to the tournament
                if self.stopping:
                    return None
                reason = f"{type(exc).__name__}: {exc}".splitlines()[0]
                (self.logs_dir / f"{fx.id}.log").write_text(reason + "\n")
                continue
            if void := void_reason(m):  # a void match is no result, whichever engine played it
                reason = void
                (self.logs_dir / f"{fx.id}.log").write_text(reason + "\n")
                continue
            r = Result.played(fx, m, attempt, time.monotonic() - t0, self.engine)
            write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
            return r
        r = Result.failed(fx, reason, 2, self.engine)
        write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
        return r

    def close(self) -> None:
        if self.pool is not None:
            pools.stop(self.pool, now=self.stopping)

    def command(self, fx: Fixture) -> list[str]:
        a = self.opts
        argv = [
            sys.executable,
            "-m",
            "arena",
            "match",
            "--home",
            fx.home,
            "--away",
            fx.away,
            "--robots",
            str(a.robots),
            "--half-time",
            str(a.half_time),
            "--seed",
            str(fx.seed),
            "--link",
            a.link,
            "--perception-latency",
            str(a.latency()),
            "--engine",
            self.engine,
            "--json",
        ]
        for p in a.link_param:
            argv += ["--link-param", p]
        return argv

    def play(self, fx: Fixture) -> Result | None:
        """Play one fixture (one retry on failure). None if stopped by Ctrl-C."""
        if self.pool is not None:
            return self.play_inprocess(fx)
        reason = ""
        timeout = 120.0 + 2.0 * self.opts.half_time  # generous: rtf >= 1 plus start-up
        for attempt in (1, 2):
            if self.stopping:
                return None
            t0 = time.monotonic()
            log = open(self.logs_dir / f"{fx.id}.log", "w")
            proc = subprocess.Popen(
                self.command(fx), stdout=subprocess.PIPE, stderr=log, text=True, start_new_session=True
            )
            with self._lock:
                self._running.add(proc)
            try:
                out, _ = proc.communicate(timeout=timeout)
            except subprocess.TimeoutExpired:
                proc.send_signal(signal.SIGINT)
                out, _ = proc.communicate()
                reason = f"timed out after {timeout:g} s"
            finally:
                with self._lock:
                    self._running.discard(proc)
                log.close()
            if self.stopping:
                return None
            if proc.returncode == 0:
                try:
                    m = json.loads(out)
                except json.JSONDecodeError:
                    reason = "the match printed no JSON"
                    continue
                if void := void_reason(m):
                    reason = void
                    continue
                r = Result.played(fx, m, attempt, time.monotonic() - t0, self.engine)
                write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
                return r
            tail = (self.logs_dir / f"{fx.id}.log").read_text(errors="replace").strip().splitlines()
            reason = reason or (tail[-1] if tail else f"exit code {proc.returncode}")
        r = Result.failed(fx, reason, 2, self.engine)
        write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
        return r

    def stop(self) -> None:
        self.stopping = True
        if self.pool is not None:
            self.close()
        with self._lock:
            running = list(self._running)
        for p in running:
            if p.poll() is None:
                p.send_signal(signal.SIGINT)  # arena match stops its whole process group


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def _worker_init() -> None:
    """An --engine inprocess worker: dies with the tournament, leaves Ctrl-C to it, imports once."""
    import ctypes

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass
    import arena.processes.engine
    import arena.tools.launch.inprocess  # noqa: F401


def _play_inprocess(cfg) -> dict:
    from arena.tools.launch.inprocess import play_match

    return play_match(cfg).to_dict()


def default_jobs() -> int:
    """One match per core.

    A lockstep match keeps its cores only ~80 % busy (it waits on its own
    critical path) and spends ~2 s starting its processes, so a second match
    fills the gaps. On the 2-core development machine, 6 matches of 2 x 60 s
    (AD, BS, AS, 2 legs) took 56.6 and 56.3 s with one at a time and 43.8 and
    46.3 s with two, with the same results and digests.
    """
    return max(1, os.cpu_count() or 1)


def play_local(jobs: int, runner: Runner, todo: list[Fixture], arrived) -> bool:
    """`jobs` (0: one per core) matches at once in a thread pool; arrived(Result) as each is in. Returns interrupted."""
    with ThreadPoolExecutor(max_workers=jobs or default_jobs()) as pool:
        pending = {pool.submit(runner.play, fx) for fx in todo}
        try:
            while pending:
                done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                for f in done:
                    r = f.result()
                    if r is not None:
                        arrived(r)
        except KeyboardInterrupt:
            runner.stop()
            for f in pending:
                f.cancel()
            return True
    return False


def run(opts: TournamentOptions) -> tuple[dict, bool]:
    """Play (or resume) the tournament. Returns (summary, interrupted)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from arena.tools.console import console as make_console

    strategies = list(opts.strategies)
    out = Path(opts.out)
    setup = settings(opts)
    if opts.resume:
        check_resume(out, setup)
    if opts.ray is not None:
        from arena.tools.experiments import cluster

        cluster.preflight(opts)  # before anything is written: a failure leaves no empty tournament behind
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "settings.json", json.dumps(setup, indent=2))
    fixtures = schedule(strategies, opts.legs, opts.seed)
    runner = Runner(opts, out)
    have = load_results(runner.matches_dir) if opts.resume else {}
    # Resume keeps finished matches; failed ones get another chance.
    todo = [fx for fx in fixtures if not (fx.id in have and have[fx.id].status == "ok")]
    results: dict[str, Result] = {fx.id: have[fx.id] for fx in fixtures if fx.id in have and have[fx.id].status == "ok"}
    if opts.resume:  # a mistyped --out would otherwise start again from nothing without a word
        print(f"arena tournament: --resume: {len(results)} of {len(fixtures)} matches kept from {out}", file=sys.stderr)
    t0 = time.monotonic()
    interrupted = False
    console = make_console(stderr=True)
    show = not opts.json and sys.stderr.isatty()
    with Progress(
        TextColumn("[bold]tournament[/]"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        TextColumn("{task.fields[last]}"),
        console=console,
        disable=not show,
        transient=False,
    ) as bar:
        task = bar.add_task("t", total=len(fixtures), completed=len(results), last="")
        # SIGTERM (a service manager, `kill`) stops like Ctrl-C: the running
        # matches are stopped and the finished results kept. Without this the
        # interpreter died at once and left the running match behind.
        previous = None
        if threading.current_thread() is threading.main_thread():
            previous = signal.signal(signal.SIGTERM, _interrupt)

        def arrived(r: Result) -> None:
            results[r.id] = r
            last = (
                f"{short(r.home)} {r.score[0]}-{r.score[1]} {short(r.away)}" if r.status == "ok" else f"{r.id} failed"
            )
            bar.update(task, advance=1, last=last)
            if not show and not opts.json:
                console.print(f"[{len(results)}/{len(fixtures)}] {last}")

        try:
            if opts.ray is not None:
                from arena.tools.experiments import cluster  # imports Ray; never without --ray

                interrupted = cluster.play(opts, runner, todo, arrived)
            else:
                interrupted = play_local(opts.jobs, runner, todo, arrived)
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)
    runner.close()
    ordered = [results[fx.id] for fx in fixtures if fx.id in results]
    try:
        summary = report(
            ordered,
            strategies,
            opts.legs,
            out,
            time.monotonic() - t0,
            opts.seed,
            engine=runner.engine,
            total=len(fixtures),
            setup=setup,
        )
    finally:
        if opts.ray is not None:
            from arena.tools.experiments import cluster

            cluster.closed()  # Ray shut down in the background while the report was written
    summary["skipped"] = len(fixtures) - len(todo)
    summary["interrupted"] = interrupted
    return summary, interrupted


def print_summary(summary: dict) -> None:
    from rich.table import Table

    from arena.tools.console import console as make_console

    c = make_console()
    t = Table(title="standings (3/1/0; by P, GD, GF)")
    for col in ("team", "W", "D", "L", "GF", "GA", "GD", "P", "rating (95 % CI)", "robot1/robot2"):
        t.add_column(col, justify="right")
    rate = {r["team"]: r for r in summary["ratings"]}
    for row in summary["table"]:
        team = row["team"]
        rr = rate[team]
        ratio = summary["coverage_ratio"][team]
        t.add_row(
            short(team),
            *(str(row[k]) for k in ("W", "D", "L", "GF", "GA", "GD", "P")),
            "-" if rr["rating"] is None else f"{rr['rating']:.0f} ({rr['ci95'][0]:.0f}..{rr['ci95'][1]:.0f})",
            "-" if ratio is None else f"{ratio:.2f}",
        )
    c.print(t)
    for note in summary["notes"]:
        c.print(f"[yellow]note:[/] {note}")
    for f in summary["failed"]:
        c.print(f"[red]failed:[/] {f['id']}: {f['reason']}")
    if "played" in summary:
        c.print(f"{summary['played']} of {plural(summary['scheduled'], 'match', 'matches')} played")
    c.print(
        f"tables, charts and per-match results in {summary['out']} "
        f"({summary['wall_seconds']:.0f} s, engine {summary.get('engine', 'processes')})"
    )
