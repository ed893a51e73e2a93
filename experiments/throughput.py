"""`arena bench throughput`: the two engines side by side on the same host.

Each run plays the same match (same seed) once with `--engine processes` and
once with `--engine inprocess`, each as its own command (`python -m arena.match`,
handed the configuration: match/child.py),
the order alternating from run to run (interleaved A/B), and every figure is
the median over the runs. Whole-process figures: the command's wall time and
its CPU (itself and every child it waited for, `RUSAGE_CHILDREN`).

Printed per engine: play rtf (simulated s / wall s from the first to the last
tick), start-up measured two ways (`LAUNCH_DEFINITIONS`), the
command's CPU per simulated second, and the tournament throughput in matches
per hour of 2 x 300 s at the default `--jobs` (one per core). That last
figure is derived, not measured, as the smaller of two bounds:
* wall: `jobs` matches at a time, each taking 600 s / rtf + its start-up and
  teardown (command wall - play wall);
* CPU: the cores' CPU seconds per hour over a match's CPU, scaled from the
  measured match to 600 simulated seconds.
The in-process engine's match is one thread (its CPU ~ its wall), so its two
bounds agree; the distributed engine's eleven processes share the cores, so
the CPU bound is the one that holds for it.

Also printed: ticks per CPU-second of each engine's whole command (start-up
included; the figure the engines' cost is compared by), the processes engine's
rtf over the in-process engine's, pair by pair, and, where the learn extra is
installed, the learning env's steps per CPU-second beside the in-process
match's ticks per CPU-second, both measured in this process over the same match
(`arena bench learn` has more), and, given `--rsoccer PYTHON` (an interpreter
with rSoccer installed), rSoccer's VSS-v0 steps per CPU-second beside our
match's ticks (experiments/rsoccer.py)."""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from msgspec import UNSET

from arena.experiments.matches import default_jobs
from arena.experiments.rsoccer import beside as rsoccer_beside
from arena.experiments.rsoccer import check as rsoccer_check
from arena.match import child
from arena.review.console import console as make_console

if TYPE_CHECKING:
    from arena.config import MatchConfig

ENGINES = ("processes", "inprocess")
RSOCCER = (
    "not measured: rSoccer's VSS-v0 needs Python 3.10 (rc-robosim, rsoccer-gym); "
    "name that interpreter with --rsoccer PYTHON to measure it beside our match"
)
# What "launch" means in the two start-up rows (printed with the table; docs/performance.md).
LAUNCH_DEFINITIONS = {
    "command": "the match's command started (`python -m arena.match`; Python's start and every import included) "
    "to the engine's first tick, clocked by this benchmark",
    "play_match": "the match's launcher called (`play_match`, in a process that has imported the engine) "
    "to the engine's first tick, as the command reports it (`startup_seconds`)",
}
TOURNAMENT_MATCH_S = 600.0  # [s] simulated: the paper's 2 x 300 s


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def play(engine: str, cfg: MatchConfig) -> dict:
    """`cfg` played by a match's command on `engine`: what the command took, and what it says."""
    cpu0, t0 = _children_cpu(), time.time()
    proc, given = child.start(cfg, engine, stderr=subprocess.PIPE)
    out, err = proc.communicate(input=given, timeout=600 + 10 * cfg.half_time)
    wall, cpu = time.time() - t0, _children_cpu() - cpu0
    if proc.returncode != 0:
        tail = (err.strip().splitlines() or [f"exit {proc.returncode}"])[-1]
        raise RuntimeError(f"the match on --engine {engine} failed: {tail}")
    r = child.decode(out)
    started = r.play_started_unix or t0
    return {
        "engine": engine,
        "seed": cfg.seed,
        "digest": r.digest,
        "rtf": r.rtf,
        "sim_seconds": r.sim_seconds,
        "ticks": r.ticks,
        "command_wall_s": round(wall, 3),
        "command_cpu_s": round(cpu, 3),
        "launch_to_first_tick_s": round(started - t0, 3),
        "play_match_to_first_tick_s": None if r.startup_seconds is UNSET else r.startup_seconds,
        "launch": None if r.launch is UNSET else r.launch,
        "overhead_s": round(wall - r.play_wall_seconds, 3),  # start-up and teardown of one match
    }


def summarise(runs: list[dict], jobs: int, cores: int) -> dict:
    keys = ("rtf", "command_wall_s", "launch_to_first_tick_s", "play_match_to_first_tick_s")
    med = {k: statistics.median(r[k] or 0.0 for r in runs) for k in keys}
    overhead = statistics.median(r["overhead_s"] for r in runs)
    cpu_per_sim = statistics.median(r["command_cpu_s"] / r["sim_seconds"] for r in runs)
    ticks_per_cpu = statistics.median((r.get("ticks") or 0) / max(1e-9, r["command_cpu_s"]) for r in runs)
    per_match_wall = TOURNAMENT_MATCH_S / med["rtf"] + overhead
    wall_bound = jobs * 3600.0 / per_match_wall
    cpu_bound = cores * 3600.0 / (cpu_per_sim * TOURNAMENT_MATCH_S)
    return {
        "rtf": round(med["rtf"], 2),
        "rtf_all": [r["rtf"] for r in runs],
        "launch_to_first_tick_s": round(med["launch_to_first_tick_s"], 3),
        "play_match_to_first_tick_s": round(med["play_match_to_first_tick_s"], 3),
        "launch": sorted({r["launch"] or "" for r in runs}),
        "command_wall_s": round(med["command_wall_s"], 3),
        "cpu_s_per_sim_s": round(cpu_per_sim, 4),
        "ticks_per_cpu_s": round(ticks_per_cpu, 1),
        "matches_per_hour": round(min(wall_bound, cpu_bound), 1),
        "matches_per_hour_wall_bound": round(wall_bound, 1),
        "matches_per_hour_cpu_bound": round(cpu_bound, 1),
    }


def bench_throughput(
    base: MatchConfig,
    runs: int,
    strategy: str,
    as_json: bool,
    learn_rates: Callable[[MatchConfig, int, str, Callable[[str], None]], dict] | None = None,
    rsoccer: str = "",
) -> int:
    """`runs` matches of `base` between two teams of `strategy`, on each engine, interleaved;
    `learn_rates`: the learning env's figures (arena/learn/bench.py), None without the learn extra;
    `rsoccer`: a Python with rSoccer installed ("" for none; experiments/rsoccer.py)."""
    console = make_console(stderr=True)
    if rsoccer:
        rsoccer_check(rsoccer)  # a wrong interpreter is told before the first match, not after the last
    cores = os.cpu_count() or 1
    jobs = default_jobs()
    played: dict[str, list[dict]] = {e: [] for e in ENGINES}
    for i in range(runs):
        seed = 1 + i
        for engine in ENGINES if i % 2 == 0 else ENGINES[::-1]:
            console.print(f"run {i + 1}/{runs}: --engine {engine}, 2 x {base.half_time:g} s, seed {seed} ...")
            r = play(engine, base.replace(seed=seed, home=strategy, away=strategy))
            played[engine].append(r)
            console.print(f"  rtf {r['rtf']:.1f}, first tick after {r['launch_to_first_tick_s']:.2f} s")
    per = {e: summarise(played[e], jobs, cores) for e in ENGINES}
    same = all(a["digest"] == b["digest"] for a, b in zip(played["processes"], played["inprocess"]))
    ratio = statistics.median(b["rtf"] / a["rtf"] for a, b in zip(played["processes"], played["inprocess"]))
    back = statistics.median(a["rtf"] / b["rtf"] for a, b in zip(played["processes"], played["inprocess"]))
    learn = learn_rates(base, runs, strategy, console.print) if learn_rates is not None else None
    vss = rsoccer_beside(base, runs, strategy, rsoccer, console.print) if rsoccer else None
    out = {
        "runs": runs,
        "match": f"{strategy} v {strategy}, {base.robots}v{base.robots}, 2 x {base.half_time:g} s, link {base.link}",
        "cores": cores,
        "jobs": jobs,
        "engines": per,
        "rtf_ratio_inprocess_over_processes": round(ratio, 2),
        "rtf_ratio_processes_over_inprocess": round(back, 3),
        "learn": learn,  # None: the learn extra is not installed
        "rsoccer": vss if vss is not None else RSOCCER,
        "digests_equal": same,
        "throughput_how": "matches/hour of 2 x 300 s = min(jobs x 3600 / (600 / rtf + start-up and teardown), "
        "cores x 3600 / (CPU s per simulated s x 600)), from the medians above",
        "launch_definitions": LAUNCH_DEFINITIONS,
        "all_runs": played,
    }
    if as_json:
        print(json.dumps(out, indent=2))
        return 0 if same else 1
    from rich.markup import escape
    from rich.table import Table

    t = Table(title=f"arena bench throughput: medians of {runs} interleaved runs, {out['match']}")
    t.add_column("metric")
    for e in ENGINES:
        t.add_column(e, justify="right")
    t.add_column("inprocess / processes", justify="right")
    p, q = per["processes"], per["inprocess"]
    t.add_row("play rtf", f"{p['rtf']:.1f}", f"{q['rtf']:.1f}", f"{ratio:.2f}x")
    t.add_row(
        escape("start-up: command launch to first tick [s] (1)"),
        f"{p['launch_to_first_tick_s']:.2f}",
        f"{q['launch_to_first_tick_s']:.2f}",
        f"{q['launch_to_first_tick_s'] / max(1e-9, p['launch_to_first_tick_s']):.2f}x",
    )
    t.add_row(
        escape(f"start-up: play_match to first tick [s] (2), {'/'.join(p['launch'])}"),
        f"{p['play_match_to_first_tick_s']:.2f}",
        f"{q['play_match_to_first_tick_s']:.2f}",
        f"{q['play_match_to_first_tick_s'] / max(1e-9, p['play_match_to_first_tick_s']):.2f}x",
    )
    t.add_row(escape("whole command [s]"), f"{p['command_wall_s']:.2f}", f"{q['command_wall_s']:.2f}", "")
    t.add_row(
        "ticks per CPU-second (whole command)",
        f"{p['ticks_per_cpu_s']:.0f}",
        f"{q['ticks_per_cpu_s']:.0f}",
        f"{q['ticks_per_cpu_s'] / max(1e-9, p['ticks_per_cpu_s']):.2f}x",
    )
    t.add_row("CPU s per simulated s", f"{p['cpu_s_per_sim_s']:.4f}", f"{q['cpu_s_per_sim_s']:.4f}", "")
    t.add_row(
        f"tournament matches/hour (2 x 300 s, --jobs {jobs})",
        f"{p['matches_per_hour']:.0f}",
        f"{q['matches_per_hour']:.0f}",
        f"{q['matches_per_hour'] / max(1e-9, p['matches_per_hour']):.2f}x",
    )
    make_console().print(t)
    console.print(f"digests equal in every pair: {'yes' if same else 'NO'}")
    console.print(f"processes rtf / in-process rtf, median of the pairs: {back:.3f}")
    if learn is None:
        console.print("learning env: not measured (install the learn extra)")
    else:
        console.print(
            f"learning env: {learn['env_steps_per_cpu_s']:.0f} steps per CPU-second against the in-process "
            f"match's {learn['match_ticks_per_cpu_s']:.0f} ticks per CPU-second (this process): "
            f"{learn['env_over_match']:.2f} x"
        )
    if vss is None:
        console.print(f"rSoccer VSS-v0: {RSOCCER}")
    else:
        console.print(
            f"rSoccer VSS-v0 (3v3, no referee, random actions): {vss['vss_steps_per_cpu_s']:.0f} steps per "
            f"CPU-second; our 3v3 match with the referee: {vss['ours_ticks_per_cpu_s']:.0f} ticks per "
            f"CPU-second: {vss['ours_over_vss']:.2f} x (median of the pairs)"
        )
    console.print("throughput derived: " + out["throughput_how"])
    console.print(f"(1) {LAUNCH_DEFINITIONS['command']}")
    console.print(f"(2) {LAUNCH_DEFINITIONS['play_match']}")
    return 0 if same else 1
