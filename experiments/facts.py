"""`arena facts`: facts about whole matches played in process, the rules
at work and play that looks like soccer.

`match_facts(cfg)` plays one match in-process (arena.match `play`, the very
`Node` code of a real match) and measures it with the one analysis of the
World/Referee streams (`arena.recording.analysis.measure`, which also serves
`arena review`); the facts are described there.

`arena facts --seeds 20` prints one line per seed and a
summary; `--home AD --away BS` picks the strategies. `--round-robin AD,AS,BD,BS
--legs 4` plays every pairing `legs` times, home and away alternating, and
prints the paper's Table 2 and the robot 1 / robot 2 coverage ratio (Fig. 9),
with the tournament's own table code (experiments/tournament.py).
"""

from __future__ import annotations

import json
import multiprocessing
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from itertools import combinations

import msgspec

from arena.config import ConfigError, MatchConfig
from arena.experiments import facts_table, pools
from arena.match import play
from arena.recording.analysis.facts import MatchFacts, measure
from arena.schemas.messages import Referee, World


def match_facts(cfg: MatchConfig) -> MatchFacts:
    result = play(cfg, watch=("world", "referee"))
    worlds = [msgspec.msgpack.decode(raw, type=World) for raw in result.frames["world"]]
    referee = {r.tick: r for r in (msgspec.msgpack.decode(raw, type=Referee) for raw in result.frames["referee"])}
    return measure(cfg, worlds, referee, result.summaries["referee"].extra, result.distance_m)


def many(cfgs: list[MatchConfig], workers: int | None = None, progress: bool = False) -> list[MatchFacts]:
    """`match_facts` of every configuration, in worker processes (spawned: no fork of threads),
    in the order given; `progress`: say on stderr as each match ends (a bar on a terminal).
    One match is played in this process: a spawned worker imported the engine again (~0.5 s of CPU)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from arena.review.console import console as make_console

    console, bar_shown = make_console(stderr=True), progress and sys.stderr.isatty()
    if len(cfgs) == 1:
        facts = match_facts(cfgs[0])
        if progress:
            c, (h, a) = cfgs[0], facts.score
            console.print(f"[1/1] seed {c.seed}: {c.home} {h}:{a} {c.away}", highlight=False)
        return [facts]
    columns = (TextColumn("[bold]facts[/]"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    context = multiprocessing.get_context("spawn")
    pool, stopped = ProcessPoolExecutor(workers or min(len(cfgs), os.cpu_count() or 1), mp_context=context), True
    try:  # Ctrl-C or SIGTERM: the workers are killed, not waited for (experiments/pools.py)
        futures = {pool.submit(match_facts, cfg): cfg for cfg in cfgs}
        with Progress(*columns, console=console, disable=not bar_shown) as bar:
            task = bar.add_task("m", total=len(cfgs))
            for done, future in enumerate(as_completed(futures), 1):
                bar.update(task, advance=1)
                if progress and not bar_shown:
                    c, (h, a) = futures[future], future.result().score
                    console.print(f"[{done}/{len(cfgs)}] seed {c.seed}: {c.home} {h}:{a} {c.away}", highlight=False)
        stopped = False
        return [f.result() for f in futures]
    finally:
        pools.stop(pool, now=stopped)


def round_robin(
    strategies: list[str], legs: int, every: MatchConfig, seed: int, workers: int
) -> tuple[list, list[MatchFacts]]:
    """Every pairing `legs` times, home and away alternating, matches like `every`, in-process;
    returns (Results, facts)."""
    from arena.experiments.fixtures import Result
    from arena.runtime import seeds

    fixtures = []
    for first, second in combinations(strategies, 2):
        for leg in range(1, legs + 1):
            home, away = (first, second) if leg % 2 == 1 else (second, first)
            s = seeds.derive(seed, "tournament", first, second, leg) % (2**31)
            fixtures.append((first, second, leg, home, away, s))
    cfgs = [every.replace(seed=s, home=h, away=a) for _, _, _, h, a, s in fixtures]
    facts = many(cfgs, workers, progress=True)
    results = [
        Result(
            id=f"{i:03d}",
            first=fst,
            second=snd,
            leg=leg,
            home=h,
            away=a,
            seed=s,
            status="ok",
            score=list(m.score),
            distance_m={f"{side}/{k}": d for side, t in zip("ab", m.teams) for k, d in enumerate(t.distance_m)},
        )
        for i, ((fst, snd, leg, h, a, s), m) in enumerate(zip(fixtures, facts))
    ]
    return results, facts


def main(
    every: MatchConfig,
    seeds: int = 20,
    first_seed: int = 0,
    workers: int | None = None,
    round_robin_of: list[str] | None = None,
    legs: int = 4,
    seed: int = 0,
    as_json: bool = False,
) -> int:
    """`arena facts`: one line per seed and a summary, or a round robin with the paper's Table 2.
    `every`: the match they all play (strategies, half, perception latency); the seeds vary."""
    from arena.strategies import registry

    workers = workers or min(2, os.cpu_count() or 1)
    if seeds < 1 or legs < 1 or workers < 1:
        raise ConfigError(f"--seeds, --legs and --workers must be at least 1 (got {seeds}, {legs}, {workers})")
    timing = every.timing
    latency = timing.perception_latency
    if not as_json:
        print(f"perception latency {latency} ticks ({latency * timing.dt * 1000:g} ms)")
    t0 = time.monotonic()
    results, names = None, [every.home, every.away]
    if round_robin_of:
        names = [registry.resolve_name(s) for s in round_robin_of]
        results, facts = round_robin(names, legs, every, seed, workers)
    else:
        cfgs = [every.replace(seed=s) for s in range(first_seed, first_seed + seeds)]
        facts = many(cfgs, workers, progress=True)
    if as_json:
        print(json.dumps(facts_table.as_json(facts, latency, time.monotonic() - t0, results, names)))
        return 0
    took = f"in {time.monotonic() - t0:.0f} s"
    if results:
        lines = [*facts_table.round_robin_lines(results, facts, names), f"{len(facts)} matches {took}"]
    else:
        lines = [*facts_table.header(bool(facts[0].teams)), *map(facts_table.line, facts)]
        lines += [*facts_table.summary(facts), took]
    print("\n".join(lines))
    return 0
