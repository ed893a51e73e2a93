"""`arena bench learn`: env steps per CPU-second against the in-process match's ticks per CPU-second.

Each run plays the same 3v3 match (referee on, both teams by `strategy`) three
ways, interleaved: as an in-process match (`--engine inprocess`), and as a
`SoccerParallelEnv` episode with 1 and with 3 controlled robots (team a's,
fixed pre-drawn actions, one step per tick, reset included). CPU seconds are
this process's (`time.process_time`), so a loaded host slows both sides alike;
the ratios are the figures to compare. Then the vector env: `SoccerEnv`s in 1
and in 2 worker processes (`SoccerVectorEnv`), stepped for the same number of
steps each: wall-clock steps per second, since it is about cores (a loaded host
distorts it), and CPU per step of the workers and this process together beside
one env's in one process (what the worker processes cost, whatever the load),
and Gymnasium's `AsyncVectorEnv`'s for comparison.
"""

from __future__ import annotations

import functools
import json
import os
import statistics
import time
from pathlib import Path

import gymnasium
import numpy as np

from arena.config import MatchConfig
from arena.experiments.rsoccer import match_rate
from arena.learn.parallel import SoccerParallelEnv
from arena.learn.single import SoccerEnv, make_vector_env
from arena.review.console import console as make_console

ACTIONS = np.random.default_rng(0).uniform(-1, 1, (64, 4)).astype(np.float32)  # cycled: no draw in the loop


def env_rate(cfg: MatchConfig, agents: list[str], frame_skip: int = 1) -> float:
    """One whole-match episode (reset included): env steps per CPU-second."""
    env = SoccerParallelEnv(
        frame_skip=frame_skip,
        agents=agents,
        home=cfg.home,
        away=cfg.away,
        robots=cfg.robots,
        half_time=cfg.half_time,
        end_on_goal=False,
        config=cfg,
    )
    t0 = time.process_time()
    env.reset(seed=cfg.seed)
    n = 0
    while env.agents:
        a = ACTIONS[n % len(ACTIONS)]
        env.step({x: a for x in env.agents})
        n += 1
    return n / (time.process_time() - t0)


def learn_rates(base: MatchConfig, runs: int, strategy: str, say) -> dict:
    """The env's steps and the in-process match's ticks per CPU-second of this process, over the same
    3v3 match (one controlled robot), interleaved: `arena bench throughput`'s learning row."""
    match: list[float] = []
    env: list[float] = []
    for i in range(runs):
        cfg = base.replace(seed=1 + i, home=strategy, away=strategy, robots=3, link="ideal")
        say(f"learn env run {i + 1}/{runs}: in-process match, then one env episode (robot a/1) ...")
        match.append(match_rate(cfg))
        env.append(env_rate(cfg, ["a/1"]))
    m, e = statistics.median(match), statistics.median(env)
    return {"match_ticks_per_cpu_s": round(m, 1), "env_steps_per_cpu_s": round(e, 1), "env_over_match": round(e / m, 3)}


def vector_rate(workers: int, steps: int, half_time: float, strategy: str, frame_skip: int = 1, gym: bool = False):
    """`workers` SoccerEnvs in their own processes, `steps` vector steps after 20 to warm up.

    Returns (wall-clock env steps per second, CPU-seconds per env step of this process and the workers
    together), both over the measured steps only: the workers' start and first match are left out.
    `gym`: Gymnasium's `AsyncVectorEnv` instead of `SoccerVectorEnv`."""
    options = dict(robot="a/1", home=strategy, away=strategy, half_time=half_time, frame_skip=frame_skip)
    if gym:
        fns = [functools.partial(SoccerEnv, **options) for _ in range(workers)]
        venv = gymnasium.vector.AsyncVectorEnv(fns, context="fork")
    else:
        venv = make_vector_env(workers, **options)
    try:
        venv.reset(seed=0)
        batch = np.repeat(ACTIONS[:1], workers, axis=0)
        for _ in range(20):  # warm up: the workers are forked and their first match built
            venv.step(batch)
        pids = [p.pid for p in venv.processes]
        cpu0 = time.process_time() + sum(_proc_cpu(p) for p in pids)
        t0 = time.perf_counter()
        for i in range(steps):
            batch[:] = ACTIONS[i % len(ACTIONS)]
            venv.step(batch)
        wall = time.perf_counter() - t0
        cpu = time.process_time() + sum(_proc_cpu(p) for p in pids) - cpu0
    finally:
        venv.close()
    return workers * steps / wall, cpu / (workers * steps)


def _proc_cpu(pid: int) -> float:
    """[s] user + system CPU time of process `pid` so far (Linux /proc; clock ticks of 10 ms)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def bench_learn(
    runs: int = 3, half_time: float = 30.0, strategy: str = "advance-dynamic", as_json: bool = False
) -> int:
    console = make_console(stderr=True)
    rates: dict[str, list[float]] = {"match": [], "env1": [], "env3": []}
    for i in range(runs):
        cfg = MatchConfig(seed=500 + i, home=strategy, away=strategy, half_time=half_time)
        console.print(f"run {i + 1}/{runs}: 2 x {half_time:g} s, 3v3, referee on ...")
        rates["match"].append(match_rate(cfg))
        rates["env1"].append(env_rate(cfg, ["a/1"]))
        rates["env3"].append(env_rate(cfg, ["a/0", "a/1", "a/2"]))
        console.print("  " + ", ".join(f"{k} {v[-1]:.0f}/cpu-s" for k, v in rates.items()))
    med = {k: statistics.median(v) for k, v in rates.items()}
    steps = int(round(2 * half_time / 0.02))
    vec = {}
    for skip in (1, 5):
        console.print(f"vector env, frame_skip {skip}: 1 worker, then 2, {steps // skip} steps each ...")
        vec[skip] = [vector_rate(w, steps // skip, half_time, strategy, skip) for w in (1, 2)]
    gym = vector_rate(1, steps, half_time, strategy, 1, gym=True)
    in_process = {
        1: med["env1"],
        5: env_rate(MatchConfig(seed=500, home=strategy, away=strategy, half_time=half_time), ["a/1"], 5),
    }
    out = {
        "runs": runs,
        "half_time": half_time,
        "strategy": strategy,
        "cpus": os.cpu_count(),
        "loadavg_1min": round(os.getloadavg()[0], 2),
        "match_ticks_per_cpu_second": round(med["match"], 1),
        "env1_steps_per_cpu_second": round(med["env1"], 1),
        "env3_steps_per_cpu_second": round(med["env3"], 1),
        "env1_ratio": round(med["env1"] / med["match"], 3),
        "env3_ratio": round(med["env3"] / med["match"], 3),
        "all": {k: [round(x, 1) for x in v] for k, v in rates.items()},
        # frame_skip -> [1 worker, 2 workers] wall-clock env steps per second, and their ratio
        "vector_steps_per_second": {str(k): [round(v[0][0], 1), round(v[1][0], 1)] for k, v in vec.items()},
        "vector_ratio": {str(k): round(v[1][0] / v[0][0], 3) for k, v in vec.items()},
        # Gymnasium's AsyncVectorEnv, 1 worker, frame_skip 1: wall steps per second, CPU microseconds per step
        "gymnasium_async_1_worker": [round(gym[0], 1), round(1e6 * gym[1], 1)],
        # frame_skip -> [1 worker, 2 workers, one env in this process] CPU microseconds per env step
        "cpu_us_per_step": {
            str(k): [round(1e6 * v[0][1], 1), round(1e6 * v[1][1], 1), round(1e6 / in_process[k], 1)]
            for k, v in vec.items()
        },
    }
    if as_json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"in-process match       {out['match_ticks_per_cpu_second']:8.0f} ticks/cpu-s")
    print(
        f"env, 1 robot           {out['env1_steps_per_cpu_second']:8.0f} steps/cpu-s  "
        f"{out['env1_ratio']:.2f} x the match (target >= 0.9)"
    )
    print(f"env, 3 robots          {out['env3_steps_per_cpu_second']:8.0f} steps/cpu-s  {out['env3_ratio']:.2f} x")
    for skip, ((v1, _), (v2, _)) in vec.items():
        c1, c2, c0 = out["cpu_us_per_step"][str(skip)]
        print(
            f"vector env, frame_skip {skip}: 1 worker {v1:6.0f} steps/s, 2 workers {v2:6.0f} steps/s (wall): "
            f"{v2 / v1:.2f} x (target >= 1.8 on 2 idle cores); CPU per step: {c1:.0f} us with 1 worker, "
            f"{c2:.0f} us with 2, {c0:.0f} us in one process"
        )
    print(f"gymnasium AsyncVectorEnv, 1 worker: CPU per step {1e6 * gym[1]:.0f} us")
    print(f"host: {out['cpus']} cpus, 1-minute load average {out['loadavg_1min']}")
    return 0
