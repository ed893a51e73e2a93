"""rSoccer's VSS-v0 beside our in-process match: `arena bench throughput --rsoccer PYTHON`.

rSoccer (rsoccer-gym with its rc-robosim simulator) needs Python 3.10 and
the old `gym`, so it runs in an interpreter of its own: `PYTHON` names it,
and `vss_rate` runs `SCRIPT` there: VSS-v0 (3v3, no referee), random actions
from its own action space, `steps` steps after one reset, episodes reset as
they end. Both sides are timed by their own process's CPU clock
(`time.process_time`), ours over the in-process match played in this process
(`match_rate`), so a loaded host slows both alike; the runs alternate.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

from arena.config import ConfigError, MatchConfig
from arena.match import play

SCRIPT = """
import json, sys, time
import gym, rsoccer_gym  # noqa: F401
env = gym.make("VSS-v0").unwrapped
env.reset()
n = int(sys.argv[1])
t0, w0 = time.process_time(), time.perf_counter()
for _ in range(n):
    if env.step(env.action_space.sample())[2]:
        env.reset()
cpu, wall = time.process_time() - t0, time.perf_counter() - w0
print(json.dumps({"steps": n, "cpu_s": cpu, "wall_s": wall}))
"""


def match_rate(cfg: MatchConfig) -> float:
    """`cfg` played in process, in this process: ticks per CPU-second."""
    t0 = time.process_time()
    play(cfg)
    return (cfg.total_ticks + 1) / (time.process_time() - t0)


def vss_rate(python: str, steps: int) -> float:
    """VSS-v0's steps per CPU-second in `python` (`SCRIPT`); a `ConfigError` naming the cause if it cannot run."""
    return _run(python, steps)


def check(python: str) -> None:
    """Before any match is played: `python` runs VSS-v0 (ten steps), or a `ConfigError` says why not."""
    _run(python, 10)


def _run(python: str, steps: int) -> float:
    if not Path(python).is_file():
        raise ConfigError(f"--rsoccer {python}: no such interpreter")
    try:
        r = subprocess.run([python, "-c", SCRIPT, str(steps)], capture_output=True, text=True, timeout=600)
    except OSError as exc:
        raise ConfigError(f"--rsoccer {python}: cannot run it: {exc.strerror}") from None
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or [f"exit {r.returncode}"])[-1]
        raise ConfigError(f"--rsoccer {python}: VSS-v0 did not run there: {last}")
    got = json.loads(r.stdout.strip().splitlines()[-1])
    return got["steps"] / max(1e-9, got["cpu_s"])


def beside(base: MatchConfig, runs: int, strategy: str, python: str, say: Callable[[str], None]) -> dict:
    """VSS-v0 and our 3v3 in-process match (referee on, `strategy` both sides), `runs` each, alternating:
    the medians per CPU-second and the median of the pair-by-pair ratios."""
    ours: list[float] = []
    theirs: list[float] = []
    for i in range(runs):
        cfg = base.replace(seed=1 + i, home=strategy, away=strategy, robots=3, link="ideal")
        steps = cfg.total_ticks + 1
        say(f"rSoccer run {i + 1}/{runs}: VSS-v0 for {steps} steps, then our match of as many ticks ...")
        theirs.append(vss_rate(python, steps))
        ours.append(match_rate(cfg))
    return {
        "python": python,
        "vss_steps_per_cpu_s": round(statistics.median(theirs), 1),
        "ours_ticks_per_cpu_s": round(statistics.median(ours), 1),
        "ours_over_vss": round(statistics.median(o / t for o, t in zip(ours, theirs)), 2),
        "all_runs": {"vss": [round(x, 1) for x in theirs], "ours": [round(x, 1) for x in ours]},
    }
