"""`arena bench experiment`: what `arena experiment run` adds to the CPU time of the matches it
plays in process, side by side with the same matches played by a bare loop, interleaved.

Each run plays one small experiment (two cells, Wi-Fi latency 0 and 50 ms, two seeds, both
ends: eight matches of `base`) twice in this process, in turn first and second: once as a
loop of the engine's call, once through the runner (`--jobs 1`: rows written as they
arrive, the progress, the bookkeeping). What the runner adds is its CPU time less that of
the matches it played (each row's `cpu_s`, measured around the engine's call); the loop is
the side-by-side check (on a busy machine two runs of the same matches differ by a few per
cent either way). The report (rows.csv, summary.json, the plots, report.md) is written once
per experiment, whatever its size, and is measured apart. Medians of `--runs` runs.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

from arena.config import MatchConfig
from arena.experiments.bench import print_metrics
from arena.review.console import console as make_console

TARGET = 0.05  # the runner may add at most 5 % to the matches' CPU time


def _file(base: MatchConfig) -> str:
    return (
        f'name = "bench"\nseeds = 2\nfirst_seed = 1000\n[base]\nhome = "{base.home}"\naway = "{base.away}"\n'
        f"half_time = {base.half_time!r}\nrobots = {base.robots}\n"
        '[factors]\n"links.wifi.latency_ms" = [0.0, 50.0]\n'
    )


def _cpu() -> float:
    return time.process_time()


def bench_experiment(base: MatchConfig, runs: int = 3, as_json: bool = False) -> int:
    from arena.experiments import design, experiment, experiment_report
    from arena.match.inprocess import play_match

    console = make_console(stderr=True)
    loop, runner, report, added = [], [], [], []
    with tempfile.TemporaryDirectory(prefix="arena-bench-exp-") as tmp:
        source = _file(base)
        (Path(tmp) / "bench.toml").write_text(source)
        exp = design.load(str(Path(tmp) / "bench.toml"))
        cfgs = [exp.match_config(m) for m in exp.matches()]
        play_match(cfgs[0])  # imports and first-call costs out of both sides
        for i in range(runs):
            console.print(
                f"run {i + 1}/{runs}: {len(cfgs)} matches of 2 x {base.half_time:g} s, by a loop and by the runner"
            )
            opts = experiment.RunOptions(jobs=1, out=Path(tmp) / f"run{i}", progress=False)
            for side in ("loop", "runner") if i % 2 == 0 else ("runner", "loop"):
                t0 = _cpu()
                if side == "loop":
                    for cfg in cfgs:
                        play_match(cfg)
                    loop.append(_cpu() - t0)
                else:
                    r = experiment.Run(exp, opts, source)
                    r.play()
                    runner.append(_cpu() - t0)
                    own = sum(row["cpu_s"] for row in r.rows.values())
                    added.append((runner[-1] - own) / own)
            t0 = _cpu()
            experiment_report.write(exp, list(r.rows.values()), opts.out)
            report.append(_cpu() - t0)
            console.print(
                f"  loop {loop[-1]:.2f} s CPU, runner {runner[-1]:.2f} s ({100 * added[-1]:+.2f} % over its "
                f"matches), report {report[-1]:.2f} s"
            )
    ratio = statistics.median(r / max(1e-9, lo) for r, lo in zip(runner, loop))
    overhead = statistics.median(added)
    out = {
        "runs": runs,
        "matches": len(cfgs),
        "half_time": base.half_time,
        "loop_cpu_s": [round(x, 3) for x in loop],
        "runner_cpu_s": [round(x, 3) for x in runner],
        "report_cpu_s": [round(x, 3) for x in report],
        "runner_added_median": round(overhead, 4),
        "runner_vs_loop_median": round(ratio - 1, 4),
        "target": TARGET,
        "within_target": overhead <= TARGET,
    }
    rows = [
        (f"{len(cfgs)} matches in a loop [CPU s]", f"{statistics.median(loop):.2f}"),
        (f"{len(cfgs)} matches through the runner [CPU s]", f"{statistics.median(runner):.2f}"),
        ("runner's CPU over its matches' own", f"{100 * overhead:+.2f} % (target <= 5 %)"),
        ("runner / loop - 1 (side by side)", f"{100 * (ratio - 1):+.1f} %"),
        ("report, once per experiment [CPU s]", f"{statistics.median(report):.2f}"),
    ]
    title = f"arena bench experiment: {'one run' if runs == 1 else f'median of {runs} runs'}"
    return print_metrics(out, title, rows, as_json)
