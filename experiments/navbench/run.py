"""Running the bench: every scheme of every scenario and every local minimum, and the `arena bench nav` entry point."""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from arena.config import ConfigError
from arena.experiments.navbench.console import print_report
from arena.experiments.navbench.loader import load
from arena.experiments.navbench.minima import run_local_minimum
from arena.experiments.navbench.plots import write_plots
from arena.experiments.navbench.report import Report
from arena.experiments.navbench.spec import BenchSpec, Clock
from arena.experiments.navbench.trials import Trial, run_trial


def run_bench(
    spec: BenchSpec,
    trials: int = 10,
    seed: int = 0,
    only: Sequence[str] = (),
    progress: Callable[[str], None] | None = None,
    clock: Clock = time.perf_counter_ns,
) -> Report:
    """Every scheme of every scenario ``trials`` times, and every local-minimum run."""
    if trials < 1:
        raise ConfigError(f"--trials must be at least 1, got {trials}")
    spec = select(spec, only)
    runs: dict[tuple[str, str], list[Trial]] = {}
    for sc in spec.scenarios:
        for scheme in sc.schemes:
            out = runs[(sc.name, scheme.name)] = []
            for t in range(trials):
                out.append(run_trial(sc, scheme, t, seed, clock))
                if progress:
                    progress(f"{sc.name} {scheme.name}")
    mins: dict[tuple[str, str], Trial] = {}
    for lm in spec.local_minima:
        for method, params in lm.methods:
            mins[(lm.name, method)] = run_local_minimum(lm, method, params, clock)
            if progress:
                progress(f"{lm.name} {method}")
    return Report(seed, trials, spec.source, runs, mins, spec)


def select(spec: BenchSpec, only: Sequence[str] = ()) -> BenchSpec:
    """``spec`` cut down to the scenarios and local minima named in ``only`` (all when empty)."""
    if not only:
        return spec
    names = {s.name for s in spec.scenarios} | {lm.name for lm in spec.local_minima}
    unknown = [n for n in only if n not in names]
    if unknown:
        raise ConfigError(f"--only {unknown[0]}: no such scenario (have: {', '.join(sorted(names))})")
    return dataclasses.replace(
        spec,
        scenarios=tuple(s for s in spec.scenarios if s.name in only),
        local_minima=tuple(lm for lm in spec.local_minima if lm.name in only),
    )


def work_units(spec: BenchSpec, trials: int) -> int:
    """How many runs ``run_bench`` makes (for the progress bar)."""
    return sum(len(s.schemes) * trials for s in spec.scenarios) + sum(len(lm.methods) for lm in spec.local_minima)


def main(
    scenarios: str | None = None,
    only: Sequence[str] = (),
    trials: int = 10,
    seed: int = 0,
    plots: str | None = None,
    as_json: bool = False,
) -> int:
    """`arena bench nav`: bad input raises ConfigError (one line on stderr, exit 2, by arena/cli.py).

    `only`: scenario names, each entry may hold several separated by commas.
    """
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    names = [s for part in only for s in part.split(",") if s]
    spec = select(load(scenarios), names)
    if trials < 1:
        raise ConfigError(f"--trials must be at least 1, got {trials}")
    if plots:
        out = Path(plots)
        if out.exists() and not out.is_dir():
            raise ConfigError(f"--plots {plots}: exists and is not a directory")
    from arena.review.console import console as make_console

    err = make_console(stderr=True)
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=err,
        disable=not err.is_terminal,
        transient=True,
    ) as bar:
        task = bar.add_task("arena bench nav", total=work_units(spec, trials))

        def tick(what: str) -> None:
            bar.update(task, advance=1, description=f"arena bench nav: {what}")

        report = run_bench(spec, trials=trials, seed=seed, progress=tick)
    if plots:
        for p in write_plots(report, plots):
            err.print(f"wrote {p}")
    if as_json:
        print(json.dumps(report.to_json(), indent=2))
    else:
        print_report(report)
    return 0
