"""`arena bench scenario`: scenario runs of 10 simulated seconds per minute, in process.

The scenario is the library's corner attack (3v3, advance-dynamic against
basic-static) cut to 10 s. Each run is timed whole, as `arena scenario run`
plays it: the match, decoding its world and referee frames, and judging. The
plain match beside it is the same configuration without the scenario (2 x 5 s),
played interleaved with the runs, so the ratio is what a scenario adds. The
runs per minute on J cores are J worker processes playing runs side by side.
"""

from __future__ import annotations

import os
import statistics
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import msgspec

from arena.config import ScenarioParams
from arena.experiments.bench import print_metrics
from arena.match import play
from arena.scenarios.library import BEHAVIOUR
from arena.scenarios.model import build, load
from arena.scenarios.runner import run_one

SECONDS = 10.0  # [s] simulated per run


def bench_scenario_of():
    sc = load(BEHAVIOUR / "corner-attack.scenario.toml")
    return build(msgspec.structs.replace(sc.spec, time_limit=SECONDS), sc.path, 0)


def _timed_run(seed: int) -> float:
    t0 = time.perf_counter()
    run_one(bench_scenario_of(), seed)
    return time.perf_counter() - t0


def bench_scenario(runs: int = 10, as_json: bool = False, jobs: int = 2) -> int:
    sc = bench_scenario_of()
    plain = sc.config(0).replace(scenario=ScenarioParams(), half_time=SECONDS / 2)
    run_one(sc, 999)  # warm: imports, first strategy tables
    scenario_s, plain_s = [], []
    for seed in range(runs):
        t0 = time.perf_counter()
        run_one(sc, seed)
        scenario_s.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        play(plain.replace(seed=seed))
        plain_s.append(time.perf_counter() - t0)
    jobs = max(1, min(jobs, os.cpu_count() or 1))
    with ProcessPoolExecutor(jobs, mp_context=get_context("fork")) as pool:
        list(pool.map(_timed_run, range(jobs)))  # warm every worker
        t0 = time.perf_counter()
        list(pool.map(_timed_run, range(jobs * runs)))
        wall = time.perf_counter() - t0
    med_s, med_p = statistics.median(scenario_s), statistics.median(plain_s)
    out = {
        "scenario": sc.name,
        "simulated_s_per_run": SECONDS,
        "runs": runs,
        "run_wall_s_median": round(med_s, 4),
        "plain_match_wall_s_median": round(med_p, 4),
        "ratio_to_plain_match": round(med_s / med_p, 3),
        "runs_per_minute_one_core": round(60.0 / med_s, 1),
        "jobs": jobs,
        "runs_per_minute_jobs": round(60.0 * jobs * runs / wall, 1),
        "cpu_count": os.cpu_count(),
        "load_average_1min": round(os.getloadavg()[0], 2),
    }
    rows = [
        ("wall time of one 10 s scenario run [s]", f"{med_s:.3f}"),
        ("wall time of the plain 10 s match [s]", f"{med_p:.3f}"),
        ("ratio scenario run / plain match", f"{med_s / med_p:.2f}"),
        ("runs per minute, one core", f"{60.0 / med_s:.0f}"),
        (f"runs per minute, {jobs} workers", f"{out['runs_per_minute_jobs']:.0f}"),
        ("load average (1 min) at the end", f"{out['load_average_1min']}"),
    ]
    return print_metrics(
        out,
        f"arena bench scenario: {'one run' if runs == 1 else f'median of {runs} runs'} of {SECONDS:g} simulated s",
        rows,
        as_json,
    )
