"""`arena bench match`: simulation speed of whole matches, as medians of several runs.
`arena bench record`: the same with and without `--record`, and the ratio.

Speed is a feature measured here, never by timed assertions in tests: the
machine is shared and noisy, so every figure is a median over `--runs` runs.
"""

from __future__ import annotations

import json
import statistics
import tempfile
from pathlib import Path

from rich.markup import escape
from rich.table import Table

from arena.config import MatchConfig
from arena.match import play, zygote
from arena.review.console import console as make_console


def bench_match(base: MatchConfig, runs: int = 3, as_json: bool = False) -> int:
    """`runs` matches of `base` (seeds 1000, 1001, ...) as separate processes: speed and start-up."""
    half_time, robots, link = base.half_time, base.robots, base.link
    console = make_console(stderr=True)
    results = []
    # Before the first router: every match's processes are forked by the zygote (match/zygote.py),
    # the first match's too (warm: the zygote has imported everything before the first launch).
    zygote.start(ready=len(base.processes()))
    for i in range(runs):
        cfg = base.replace(seed=1000 + i)
        console.print(f"run {i + 1}/{runs}: 2 x {half_time:g} s, {robots}v{robots}, link {link} ...")
        r = play(cfg, engine="processes")
        results.append(r)
        console.print(
            f"  rtf {r.rtf:.1f}x, {1000 * r.play_wall_seconds / max(1, r.ticks):.3f} ms/tick, "
            f"first tick {r.startup_seconds}s after play_match ({r.launch})"
        )
    rtf = statistics.median(r.rtf for r in results)
    ms_tick = statistics.median(1000 * r.play_wall_seconds / max(1, r.ticks) for r in results)
    startup = statistics.median(r.wall_seconds - r.play_wall_seconds for r in results)
    per_kind: dict[str, list[float]] = {}
    for r in results:
        for p in r.processes:
            if p.tick_us_median is not None:
                per_kind.setdefault(p.kind, []).append(p.tick_us_median)
    out = {
        "runs": runs,
        "half_time": half_time,
        "robots": robots,
        "link": link,
        "rtf_median": rtf,
        "rtf_all": [r.rtf for r in results],
        "ms_per_tick_median": round(ms_tick, 4),
        "ticks_per_second": round(1000.0 / ms_tick, 1),
        "startup_seconds_median": round(startup, 2),
        # play_match called (everything imported) to the engine's first tick; how the processes started
        "launch_to_first_tick_median": statistics.median(r.startup_seconds or 0.0 for r in results),
        "launch_to_first_tick_all": [r.startup_seconds for r in results],
        "launch": [r.launch for r in results],
        "work_us_per_tick_median": {k: round(statistics.median(v), 1) for k, v in per_kind.items()},
    }
    rows = [
        ("real-time factor (sim s / wall s)", f"{rtf:.1f}x"),
        ("wall time per tick, all processes [ms]", f"{ms_tick:.3f}"),
        ("ticks per second", f"{1000.0 / ms_tick:.0f}"),
        ("process start-up and teardown (wall - play wall) [s]", f"{startup:.2f}"),
        (
            "launch (play_match called) to first tick [s]",
            f"{out['launch_to_first_tick_median']:.3f} ({', '.join(sorted(set(out['launch'])))})",
        ),
    ]
    rows += [(f"own work per tick, {k} [us]", f"{v:.0f}") for k, v in out["work_us_per_tick_median"].items()]
    return print_metrics(
        out, f"arena bench match: {'one run' if runs == 1 else f'median of {runs} runs'}", rows, as_json
    )


def print_metrics(out: dict, title: str, rows: list[tuple[str, str]], as_json: bool) -> int:
    """One JSON object, or a table of (metric, value) rows."""
    if as_json:
        print(json.dumps(out, indent=2))
        return 0
    t = Table(title=title)
    t.add_column("metric")
    t.add_column("value", justify="right")
    for name, value in rows:
        t.add_row(escape(name), value)  # "[s]" is a unit, not rich markup
    make_console().print(t)
    return 0


def bench_record(base: MatchConfig, runs: int = 3, as_json: bool = False) -> int:
    """The cost of `--record`: matches of `base` with and without a recorder, interleaved."""
    half_time, robots, link = base.half_time, base.robots, base.link
    console = make_console(stderr=True)
    plain, recorded, sizes = [], [], []
    zygote.start(ready=len(base.processes()) + 1)
    with tempfile.TemporaryDirectory(prefix="arena-bench-") as tmp:
        for i in range(runs):
            cfg = base.replace(seed=1000 + i)
            path = Path(tmp) / f"run{i}.mcap"
            # Alternate which goes first, so that drift in the machine's load favours neither.
            order = [(False, ""), (True, str(path))]
            for rec, record in order if i % 2 == 0 else reversed(order):
                r = play(cfg, engine="processes", record=record)
                (recorded if rec else plain).append(r)
                console.print(f"run {i + 1}/{runs} {'recorded' if rec else 'plain   '}: rtf {r.rtf:.1f}x")
            sizes.append(path.stat().st_size)
    rtf_plain = statistics.median(r.rtf for r in plain)
    rtf_rec = statistics.median(r.rtf for r in recorded)
    wall_plain = statistics.median(r.wall_seconds for r in plain)
    wall_rec = statistics.median(r.wall_seconds for r in recorded)
    out = {
        "runs": runs,
        "half_time": half_time,
        "robots": robots,
        "link": link,
        "rtf_median_plain": rtf_plain,
        "rtf_median_recorded": rtf_rec,
        "rtf_ratio": round(rtf_rec / rtf_plain, 3),
        "cost_percent": round(100.0 * (1.0 - rtf_rec / rtf_plain), 1),
        "rtf_all_plain": [r.rtf for r in plain],
        "rtf_all_recorded": [r.rtf for r in recorded],
        "wall_seconds_median_plain": wall_plain,
        "wall_seconds_median_recorded": wall_rec,
        "recorder_cpu_s_median": statistics.median(
            p.cpu_s for r in recorded for p in r.processes if p.kind == "recorder" and p.cpu_s is not None
        ),
        "file_mb_median": round(statistics.median(sizes) / 1e6, 2),
    }
    rows = [
        ("real-time factor, plain", f"{rtf_plain:.1f}x"),
        ("real-time factor, --record", f"{rtf_rec:.1f}x"),
        ("ratio recorded / plain", f"{out['rtf_ratio']:.3f}"),
        ("cost of recording", f"{out['cost_percent']:.1f} %"),
        ("wall seconds (with start-up), plain", f"{wall_plain:.2f}"),
        ("wall seconds (with start-up), --record", f"{wall_rec:.2f}"),
        ("recorder CPU [s]", f"{out['recorder_cpu_s_median']:.2f}"),
        ("MCAP file [MB]", f"{out['file_mb_median']:.2f}"),
    ]
    return print_metrics(
        out, f"arena bench record: {'one run' if runs == 1 else f'median of {runs} runs'} each", rows, as_json
    )


def robot_step_us(strategy: str = "advance-dynamic", batches: int = 200, per_batch: int = 50) -> dict[str, float]:
    """Median wall time [us] of one robot control step (perception, behaviour, navigation) and of F-SFM alone.

    The robot brain is fed the conformance suite's scripted senses (every robot
    and the ball in view) and its base station's orders, so that perception,
    role logic and navigation with 5 obstacles all run; F-SFM is timed with the
    same 5 obstacles.
    """
    import random
    import time

    from arena.navigation import fsfm
    from arena.strategies import conformance, registry
    from arena.strategies.base import RobotContext, TeamContext

    cfg = MatchConfig()
    s = registry.get(strategy)
    team = s.make_team(TeamContext(cfg=cfg, team="a", rng=random.Random(0)))
    inputs = list(conformance.scripted_inputs(cfg, seed=0))
    _, senses0 = inputs[0]
    reports = {
        n: s.make_robot(RobotContext(cfg=cfg, team="a", n=n, rng=random.Random(0))).report(0, senses0["a"][n])
        for n in range(cfg.robots)
    }
    orders = team.step(1, reports, inputs[10][0])
    robots = {n: s.make_robot(RobotContext(cfg=cfg, team="a", n=n, rng=random.Random(0))) for n in range(cfg.robots)}
    samples: list[float] = []
    k = 0
    for b in range(batches):
        n = 1 + b % (cfg.robots - 1)
        brain = robots[n]
        t0 = time.perf_counter()
        for _ in range(per_batch):
            _, senses = inputs[k % len(inputs)]
            brain.step(k, senses["a"][n], orders[n])
            k += 1
        samples.append((time.perf_counter() - t0) / per_batch * 1e6)
    obstacles = [(1.0, 0.5), (-0.8, 0.9), (2.5, -1.0), (0.3, -0.6), (3.0, 2.0)]
    params = fsfm.FSFMParams()
    nav: list[float] = []
    for _ in range(batches):
        t0 = time.perf_counter()
        for _ in range(per_batch):
            fsfm.step((0.0, 0.0), (0.5, 0.1), (5.0, 1.0), obstacles, params)
        nav.append((time.perf_counter() - t0) / per_batch * 1e6)
    return {"robot_step_us": statistics.median(samples), "fsfm_step_us": statistics.median(nav)}


def bench_robot(strategy: str = "advance-dynamic", as_json: bool = False) -> int:
    """`arena bench robot`: median us per robot control step and per F-SFM step (5 obstacles)."""
    out = {"strategy": strategy, **{k: round(v, 1) for k, v in robot_step_us(strategy).items()}}
    if as_json:
        print(json.dumps(out, indent=2))
        return 0
    t = Table(title=f"arena bench robot: {strategy}, medians of 200 batches of 50 steps")
    t.add_column("metric")
    t.add_column("value", justify="right")
    t.add_row(r"robot control step (perception, behaviour, navigation) \[us]", f"{out['robot_step_us']:.1f}")
    t.add_row(r"F-SFM step, 5 obstacles \[us]", f"{out['fsfm_step_us']:.1f}")
    make_console().print(t)
    return 0
