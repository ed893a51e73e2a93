"""`arena experiment tune`: search a strategy's parameters for the most points against opponents.

A measurement of a set of values plays the tuned strategy with those values
(as its team's `MatchConfig.params`) against every opponent, on a list of
seeds, each seed with the ends swapped (the tuned team as a, then as b); its
value is the mean points per match (3 a win, 1 a draw).

* `spsa` (the default; experiments/spsa.py): iteration k measures
  theta + c_k delta and theta - c_k delta on the same fresh seeds (a paired
  match set: `seeds` seeds x 2 ends x each opponent, twice) and steps.
* `optuna` (extra `tune`): Optuna's TPE sampler, seeded; every trial is
  measured on the same seeds (common random numbers, so trials differ by their
  values, not the noise). It takes string and bool parameters (a navigator)
  that SPSA cannot, and suits a few parameters with a budget of many trials.

Resumable: `tune.json` in `--out` holds the settings and every finished
iteration (Optuna's trials are in `optuna.log`), written after each; `--resume`
continues where it stopped and refuses other settings. At the end the best
values (SPSA's last iterate, Optuna's best trial) are measured again against
the defaults on fresh seeds, `REMEASURE_FROM` on, that no iteration used: the
gain in points per match with its 95 % interval (bootstrap over seeds, paired:
both play the same seeds and ends).
"""

from __future__ import annotations

import dataclasses
import json
import math
import random
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from arena.config import ConfigError, MatchConfig
from arena.experiments.fixtures import write_atomic
from arena.experiments.spsa import Gains, Space, delta, perturbed, step

REMEASURE_FROM = 1_000_000  # the re-measurement's seeds start here; tuning seeds stay below
BOOT = 2000  # bootstrap resamples of the gain's interval
BINDING = ("strategy", "opponents", "params", "method", "seeds", "gains", "seed", "base")


@dataclass(frozen=True)
class TuneOptions:
    strategy: str  # canonical name
    opponents: tuple[str, ...]
    names: tuple[str, ...]  # the tuned parameters
    iterations: int = 20  # SPSA iterations, or Optuna trials
    seeds: int = 1  # seeds per iteration (SPSA) or per trial (Optuna), each played with both ends
    gains: Gains = field(default_factory=Gains)
    seed: int = 0  # SPSA's perturbations, Optuna's sampler; tuning seeds are seed, seed + 1, ...
    remeasure: int = 10  # fresh seeds for the final measurement
    method: str = "spsa"
    jobs: int = 0
    ray: str | None = None  # None: this machine; "": a local Ray instance; "auto" or HOST:PORT
    out: Path = Path("tune")
    resume: bool = False
    progress: bool = True


def check(opts: TuneOptions, params: dict) -> None:
    if opts.iterations < 1 or opts.seeds < 1 or opts.remeasure < 2:
        raise ConfigError("--iterations and --seeds must be at least 1, --remeasure at least 2")
    if opts.seed < 0 or opts.seed + opts.iterations * opts.seeds > REMEASURE_FROM:
        raise ConfigError(f"--seed and the tuning seeds must stay within 0..{REMEASURE_FROM} (the fresh seeds follow)")
    if not opts.opponents:
        raise ConfigError("--opponents: give at least one strategy to play against")
    g = opts.gains
    if not (g.a > 0 and 0 < g.c <= 0.5 and g.A >= 0 and all(map(math.isfinite, (g.a, g.c, g.A)))):
        raise ConfigError(f"--a must be > 0, --c in (0, 0.5] and --A >= 0, got {g.a}, {g.c}, {g.A}")
    for name in opts.names:
        p = params[name]
        if opts.method == "spsa" and p.type not in ("int", "float"):
            raise ConfigError(f"--params {name}: SPSA tunes numbers only; {name} is {p.type} (use --method optuna)")


def settings(opts: TuneOptions, base: MatchConfig) -> dict:
    """What decides the matches and the search: --resume refuses to mix other values in."""
    keep = base.to_dict()
    for k in ("seed", "home", "away", "params", "tap", "live", "pace", "external", "realtime"):
        keep.pop(k, None)
    setup = {
        "strategy": opts.strategy,
        "opponents": list(opts.opponents),
        "params": list(opts.names),
        "method": opts.method,
        "iterations": opts.iterations,
        "seeds": opts.seeds,
        "gains": asdict(opts.gains),
        "seed": opts.seed,
        "remeasure": opts.remeasure,
        "base": keep,
    }
    return json.loads(json.dumps(setup))  # as tune.json gives it back (lists, not tuples)


def match_set(base: MatchConfig, opts: TuneOptions, values: dict, seeds: list[int]) -> list[tuple[MatchConfig, str]]:
    """(configuration, the tuned team's side) of one measurement: each opponent, seed and end."""
    out = []
    for opp in opts.opponents:
        for s in seeds:
            for side in ("a", "b"):
                home, away = (opts.strategy, opp) if side == "a" else (opp, opts.strategy)
                out.append((base.replace(seed=s, home=home, away=away, params={side: values} if values else {}), side))
    return out


def points(m: dict, side: str) -> tuple[int, int]:
    """(points, goal difference) of `side` in a played match."""
    mine, theirs = (m["score"][0], m["score"][1]) if side == "a" else (m["score"][1], m["score"][0])
    return (3 if mine > theirs else 1 if mine == theirs else 0), mine - theirs


class TuneError(RuntimeError):
    """A match that could not be played (twice): the run stops, what is done stays (--resume)."""


class Player:
    """Plays lists of configurations through the experiments' executor (experiments/executor.py):
    in this process (--jobs 1), on a pool of worker processes, or as Ray tasks (--ray); every match by
    `experiment.play_one`, the in-process engine. A match that fails twice stops the run with its reason
    (what is done stays: --resume)."""

    def __init__(self, jobs: int, ray: str | None, log_dir: Path):
        from arena.experiments.executor import Executor

        log_dir.mkdir(parents=True, exist_ok=True)
        self.executor = Executor(jobs, ray, log_dir)

    def play(self, cfgs: list[MatchConfig], done=None) -> list[dict]:
        ex = self.executor
        results: list[dict | None] = [None] * len(cfgs)
        tries = [0] * len(cfgs)
        todo = list(range(len(cfgs)))
        while todo or ex.pending:
            while todo and ex.pending < ex.capacity:
                i = todo.pop(0)
                tries[i] += 1
                ex.submit(i, (cfgs[i], "inprocess", False))
            for i, got, reason in ex.wait():
                if got is not None:
                    results[i] = got
                    if done:
                        done()
                elif tries[i] < 2:
                    todo.append(i)
                else:
                    ex.abandon()
                    c = cfgs[i]
                    raise TuneError(f"match seed {c.seed} {c.home} v {c.away} failed twice: {reason}")
        return results  # type: ignore[return-value]

    def close(self, stopped: bool = False) -> None:
        self.executor.__exit__(KeyboardInterrupt if stopped else None, None, None)


def measure(player: Player, sets: list[list[tuple[MatchConfig, str]]], done=None) -> list[list[tuple[int, int]]]:
    """Play several measurements' matches together (they fill the pool); per measurement its (points, gd)."""
    flat = [cfg for s in sets for cfg, _ in s]
    got = player.play(flat, done)
    out, i = [], 0
    for s in sets:
        out.append([points(got[i + j], side) for j, (_, side) in enumerate(s)])
        i += len(s)
    return out


def mean(xs) -> float:
    xs = list(xs)
    return sum(xs) / len(xs) if xs else 0.0


def bootstrap_ci(diffs: list[float], seed: int, boot: int = BOOT) -> tuple[float, float]:
    """95 % percentile interval of the mean of `diffs` (one per seed), resampled with a seeded RNG."""
    rng = random.Random(f"tune-boot:{seed}")
    n = len(diffs)
    means = sorted(mean(diffs[rng.randrange(n)] for _ in range(n)) for _ in range(boot))
    return means[int(0.025 * boot)], means[int(0.975 * boot) - 1]


def _load(opts: TuneOptions, setup: dict) -> dict:
    path = opts.out / "tune.json"
    if not opts.resume:
        return {"settings": setup, "iterations": [], "theta": None, "remeasure": None}
    if not path.exists():
        raise ConfigError(f"--resume: {opts.out} holds no tune.json, so there is nothing to resume")
    try:
        state = json.loads(path.read_text())
        before = state["settings"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ConfigError(f"--resume: cannot read {path}: {exc}") from None
    # A defaults to a tenth of --iterations: a longer run resumed keeps the A it started with.
    if isinstance(before.get("gains"), dict) and "A" in before["gains"]:
        setup["gains"]["A"] = before["gains"]["A"]
    diffs = [k for k in BINDING if before.get(k) != setup[k]]
    if diffs:
        raise ConfigError(
            f"--resume: {opts.out} was tuned with other settings ({', '.join(diffs)} differ); "
            "give the same ones, or another --out"
        )
    state["settings"] = setup  # more --iterations or another --remeasure may continue a run
    if len(state["iterations"]) < opts.iterations:
        state["remeasure"] = None
    return state


def _save(opts: TuneOptions, state: dict) -> None:
    write_atomic(opts.out / "tune.json", json.dumps(state, indent=1))


def _spsa(base, opts, space, state, player, bar) -> dict:
    gains = opts.gains
    theta = state["theta"] if state["theta"] is not None else space.to_unit(space.defaults())
    for k in range(len(state["iterations"]), opts.iterations):
        d = delta(opts.seed, k, len(space.params))
        plus, minus = perturbed(theta, d, gains.c_k(k))
        seeds = [opts.seed + k * opts.seeds + j for j in range(opts.seeds)]
        vp, vm = space.values(plus), space.values(minus)
        bar.iteration(k)
        rp, rm = measure(player, [match_set(base, opts, vp, seeds), match_set(base, opts, vm, seeds)], bar.done)
        yp, ym = mean(p for p, _ in rp), mean(p for p, _ in rm)
        theta = step(theta, d, k, yp, ym, gains)
        row = {"k": k, "seeds": seeds, "plus": vp, "minus": vm, "y_plus": yp, "y_minus": ym}
        state["iterations"].append({**row, "values": space.values(theta)})
        state["theta"] = theta
        _save(opts, state)
        bar.said(f"iteration {k + 1}: {yp:.2f} v {ym:.2f} points a match")
    return space.values(theta)


def _suggest(trial, p):
    if p.type == "float":
        return trial.suggest_float(p.name, p.low, p.high)
    if p.type == "int":
        return trial.suggest_int(p.name, int(p.low), int(p.high))
    if p.type == "bool":
        return trial.suggest_categorical(p.name, [False, True])
    return trial.suggest_categorical(p.name, list(p.choices) or [p.default])


def _optuna(base, opts, space, state, player, bar) -> dict:
    try:
        import optuna
        from optuna.storages import JournalStorage
        from optuna.storages.journal import JournalFileBackend
    except ImportError:
        raise ConfigError("--method optuna needs Optuna: pip install 'soccer-arena[tune]'") from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = JournalStorage(JournalFileBackend(str(opts.out / "optuna.log")))
    sampler = optuna.samplers.TPESampler(seed=opts.seed)
    study = optuna.create_study(
        study_name="tune", storage=storage, sampler=sampler, direction="maximize", load_if_exists=True
    )
    if not study.trials:
        study.enqueue_trial(space.defaults())  # the first trial: the defaults, the point to beat
    seeds = [opts.seed + j for j in range(opts.seeds)]  # every trial the same seeds: common random numbers
    done = sum(t.state == optuna.trial.TrialState.COMPLETE for t in study.trials)
    for k in range(done, opts.iterations):
        trial = study.ask()
        values = {p.name: _suggest(trial, p) for p in space.params}
        bar.iteration(k)
        (res,) = measure(player, [match_set(base, opts, values, seeds)], bar.done)
        y = mean(p for p, _ in res)
        study.tell(trial, y)
        state["iterations"].append({"k": k, "seeds": seeds, "values": values, "y": y})
        _save(opts, state)
        bar.said(f"trial {k + 1}: {y:.2f} points a match")
    return dict(study.best_trial.params)


def remeasure(base, opts, best: dict, player, bar) -> dict:
    """The best values against the defaults on fresh seeds, the same seeds and ends for both."""
    seeds = [REMEASURE_FROM + j for j in range(opts.remeasure)]
    bar.iteration(-1)
    tuned, plain = measure(player, [match_set(base, opts, best, seeds), match_set(base, opts, {}, seeds)], bar.done)
    per_seed = 2 * len(opts.opponents)  # matches per seed: each opponent, both ends
    order = [(opp, s) for opp in opts.opponents for s in seeds for _ in (0, 1)]  # match_set's order
    diffs: dict[int, float] = {}
    for (_, s), (pt, _), (pd, _) in zip(order, tuned, plain):
        diffs[s] = diffs.get(s, 0.0) + (pt - pd) / per_seed
    gain = mean(diffs.values())
    lo, hi = bootstrap_ci(list(diffs.values()), opts.seed)
    return {
        "seeds": [seeds[0], seeds[-1]],
        "matches": 2 * len(tuned),
        "best_points": round(mean(p for p, _ in tuned), 4),
        "default_points": round(mean(p for p, _ in plain), 4),
        "best_goal_diff": round(mean(g for _, g in tuned), 4),
        "default_goal_diff": round(mean(g for _, g in plain), 4),
        "gain": round(gain, 4),
        "ci95": [round(lo, 4), round(hi, 4)],
    }


class Bar:
    """The terminal's progress: matches done of all, the rate, the time left, the last iteration."""

    def __init__(self, total: int, done: int, show: bool):
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        from arena.review.console import console

        self.console = console(stderr=True)
        self.show = show
        self.progress = Progress(
            TextColumn("[bold]tune[/] {task.fields[where]}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[rate]}"),
            TimeRemainingColumn(),
            TextColumn("{task.fields[last]}"),
            console=self.console,
            disable=not show,
        )
        self.task = self.progress.add_task("t", total=total, completed=done, where="", rate="", last="")
        self.t0, self.n = time.monotonic(), 0

    def iteration(self, k: int) -> None:
        self.progress.update(self.task, where="re-measuring" if k < 0 else f"iteration {k + 1}")

    def done(self) -> None:
        self.n += 1
        rate = self.n / max(1e-9, time.monotonic() - self.t0) * 60
        self.progress.update(self.task, advance=1, rate=f"{rate:.1f} matches/min")

    def said(self, line: str) -> None:
        self.progress.update(self.task, last=line)
        if not self.show:
            print(f"arena experiment tune: {line}", file=sys.stderr, flush=True)

    def __enter__(self) -> Bar:
        self.progress.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        self.progress.__exit__(*exc)


def run(base: MatchConfig, opts: TuneOptions, space: Space) -> tuple[dict, bool]:
    """Tune (or resume), re-measure, write the files. Returns (result, interrupted)."""
    setup = settings(opts, base)
    state = _load(opts, setup)
    opts = dataclasses.replace(opts, gains=Gains(**state["settings"]["gains"]))
    opts.out.mkdir(parents=True, exist_ok=True)
    _save(opts, state)
    per = match_count(opts)
    left = max(0, opts.iterations - len(state["iterations"])) * per + 4 * len(opts.opponents) * opts.remeasure
    player = Player(opts.jobs, opts.ray, opts.out / "logs")
    interrupted = False
    t0 = time.monotonic()
    try:
        with Bar(left, 0, opts.progress and sys.stderr.isatty()) as bar:
            best = (_spsa if opts.method == "spsa" else _optuna)(base, opts, space, state, player, bar)
            state["best"] = best
            state["remeasure"] = remeasure(base, opts, best, player, bar)
            _save(opts, state)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        player.close(stopped=interrupted)
    result = summary(opts, space, state, time.monotonic() - t0)
    if not interrupted:
        from arena.experiments.tune_report import write_outputs

        write_outputs(opts, space, state, result)
    return result, interrupted


def match_count(opts: TuneOptions) -> int:
    """Matches of one iteration: each opponent, seed and end; SPSA measures twice."""
    return (2 if opts.method == "spsa" else 1) * len(opts.opponents) * opts.seeds * 2


def summary(opts: TuneOptions, space: Space, state: dict, wall: float) -> dict:
    return {
        "strategy": opts.strategy,
        "opponents": list(opts.opponents),
        "method": opts.method,
        "iterations": len(state["iterations"]),
        "defaults": space.defaults(),
        "best": state.get("best"),
        "remeasure": state.get("remeasure"),
        "out": str(opts.out),
        "wall_seconds": round(wall, 1),
    }
