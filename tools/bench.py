"""`arena bench match`: simulation speed of whole matches, as medians of several runs.

Speed is a feature measured here, never by timed assertions in tests: the
machine is shared and noisy, so every figure is a median over `--runs` runs.
"""

from __future__ import annotations

import argparse
import json
import statistics

from rich.console import Console
from rich.table import Table

from arena.runtime.config import MatchConfig
from arena.tools import launcher


def bench_match(args: argparse.Namespace) -> int:
    console = Console(stderr=True)
    runs = []
    for i in range(args.runs):
        cfg = MatchConfig(seed=1000 + i, robots=args.robots, half_time=args.half_time, link=args.link)
        console.print(f"run {i + 1}/{args.runs}: 2 x {args.half_time:g} s, {args.robots}v{args.robots}, link {args.link} ...")
        r = launcher.play_match(cfg)
        runs.append(r)
        console.print(f"  rtf {r['rtf']:.1f}x, {1000 * r['play_wall_seconds'] / max(1, r['ticks']):.3f} ms/tick")
    rtf = statistics.median(r["rtf"] for r in runs)
    ms_tick = statistics.median(1000 * r["play_wall_seconds"] / max(1, r["ticks"]) for r in runs)
    startup = statistics.median(r["wall_seconds"] - r["play_wall_seconds"] for r in runs)
    per_kind: dict[str, list[float]] = {}
    for r in runs:
        for p in r["processes"]:
            if p["tick_us_median"] is not None:
                per_kind.setdefault(p["kind"], []).append(p["tick_us_median"])
    out = {
        "runs": args.runs,
        "half_time": args.half_time,
        "robots": args.robots,
        "link": args.link,
        "rtf_median": rtf,
        "rtf_all": [r["rtf"] for r in runs],
        "ms_per_tick_median": round(ms_tick, 4),
        "ticks_per_second": round(1000.0 / ms_tick, 1),
        "startup_seconds_median": round(startup, 2),
        "work_us_per_tick_median": {k: round(statistics.median(v), 1) for k, v in per_kind.items()},
    }
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    t = Table(title=f"arena bench match: median of {args.runs} runs")
    t.add_column("metric")
    t.add_column("value", justify="right")
    t.add_row("real-time factor (sim s / wall s)", f"{rtf:.1f}x")
    t.add_row("ms per tick (all 10 processes)", f"{ms_tick:.3f}")
    t.add_row("ticks per second", f"{1000.0 / ms_tick:.0f}")
    t.add_row("process start-up [s]", f"{startup:.2f}")
    for k, v in out["work_us_per_tick_median"].items():
        t.add_row(f"own work per tick, {k} [us]", f"{v:.0f}")
    Console().print(t)
    return 0
