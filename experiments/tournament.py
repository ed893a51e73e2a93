"""`arena tournament`: round-robins of strategies, with the paper's tables and statistics.

Every pairing of the strategies plays `legs` matches, alternating home and
away, each with a seed derived from the tournament seed. Every match is a full,
isolated match process group (`python -m arena.match`); `--jobs` of them run at once. Each
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

import json
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from arena.config import MatchConfig
from arena.experiments.fixtures import Result, load_results, schedule, short, write_atomic
from arena.experiments.matches import Runner, play_local
from arena.experiments.tournament_report import report, show_value

# Settings that decide what a match is: --resume refuses to mix results played with other values.
BINDING = (
    "strategies",
    "legs",
    "half_time",
    "robots",
    "link",
    "link_overrides",
    "perception_latency",
    "config",
    "params",
    "seed",
)
# What a settings.json written before a binding setting existed was played with.
LEGACY = {"perception_latency": 0, "config": {}, "params": {}}


@dataclass(frozen=True)
class TournamentOptions:
    """What `arena tournament` plays and how (arena/commands/tournament.py builds one from its flags):
    `base` is every match's configuration, each fixture setting its seed, home and away (`match_config`)."""

    strategies: tuple[str, ...]  # resolved names, in the order given
    base: MatchConfig = field(default_factory=MatchConfig)
    params: tuple[tuple[str, str, object], ...] = ()  # (strategy, name, value), checked: --param STRATEGY.NAME=V
    legs: int = 10
    seed: int = 0  # the tournament's: the matches' seeds derive from it
    jobs: int = 0  # 0: one per core
    out: Path = Path("tournament")
    resume: bool = False
    json: bool = False
    engine: str = "processes"
    ray: str | None = None  # None: no Ray; "": a local instance; else auto or HOST:PORT
    ray_runtime_env: str | None = None  # JSON text

    def match_config(self, seed: int, home: str, away: str) -> MatchConfig:
        """One fixture's match: the base configuration with its seed and teams, each team the parameter
        values of the strategy it plays."""
        by = self.params_by_strategy()
        params = {**self.base.params, **{t: dict(by[s]) for t, s in (("a", home), ("b", away)) if s in by}}
        return self.base.replace(seed=seed, home=home, away=away, params=params)

    def params_by_strategy(self) -> dict[str, dict[str, object]]:
        """Strategy -> its parameter values (--param), whichever side it plays."""
        out: dict[str, dict[str, object]] = {}
        for strategy, name, value in self.params:
            out.setdefault(strategy, {})[name] = value
        return out


# Set per fixture, or recorded by settings() on their own: not part of its "config".
PER_MATCH = {"seed", "home", "away", "robots", "half_time", "link", "link_overrides"}
TRANSPORT = {"perception_latency", "batch"}  # timing keys recorded on their own, or no part of the digests


def config_changes(base: MatchConfig) -> dict:
    """What the base configuration sets apart from the defaults, beyond the settings recorded on
    their own: {section: {key: value}} of field, robot, ball, sensor, rules, timing, ...
    ({} for a tournament of defaults)."""
    now, default = base.to_dict(), MatchConfig().to_dict()
    out = {}
    for key, value in now.items():
        if key in PER_MATCH or value == default[key]:
            continue
        if isinstance(value, dict) and isinstance(default[key], dict):
            changed = {k: v for k, v in value.items() if v != default[key].get(k)}
            if key == "timing":
                changed = {k: v for k, v in changed.items() if k not in TRANSPORT}
            if changed:
                out[key] = changed
        else:
            out[key] = value
    return out


def settings(opts: TournamentOptions) -> dict:
    """Everything needed to play the tournament again (tournament.json, report.md, --resume's check)."""
    from arena.runtime.version import package_version

    base = opts.base
    return {
        "strategies": list(opts.strategies),
        "legs": opts.legs,
        "half_time": float(base.half_time),
        "robots": base.robots,
        "link": base.link,
        "link_overrides": base.link_overrides,
        "perception_latency": base.timing.perception_latency,
        "config": config_changes(base),
        "params": opts.params_by_strategy(),
        "seed": opts.seed,
        "engine": opts.engine,
        "version": package_version(),
    }


def check_resume(out: Path, now: dict) -> None:
    """ConfigError naming every setting that differs from the ones `out` was played with."""
    from arena.config import ConfigError

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
    flag = {
        "link_overrides": "link-param",
        "half_time": "half-time",
        "perception_latency": "perception-latency",
        "params": "param",
    }
    diffs = [
        f"--{flag.get(k, k)} {show_value(before.get(k, LEGACY.get(k)))} there, {show_value(now[k])} now"
        for k in BINDING
        if before.get(k, LEGACY.get(k)) != now[k]
    ]
    if diffs:
        raise ConfigError(
            f"--resume: {out} was played with different settings: {'; '.join(diffs)} "
            "(give the same settings, or another --out)"
        )


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def run(opts: TournamentOptions) -> tuple[dict, bool]:
    """Play (or resume) the tournament. Returns (summary, interrupted)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from arena.review.console import console as make_console

    strategies = list(opts.strategies)
    out = Path(opts.out)
    setup = settings(opts)
    if opts.resume:
        check_resume(out, setup)
    if opts.ray is not None:
        from arena.experiments import cluster

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
                from arena.experiments import cluster  # imports Ray; never without --ray

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
            from arena.experiments import cluster

            cluster.closed()  # Ray shut down in the background while the report was written
    summary["skipped"] = len(fixtures) - len(todo)
    summary["interrupted"] = interrupted
    return summary, interrupted
