"""Facts about whole matches, for the rules acceptance (issue 3) and its report.

`match_facts(cfg)` plays one match in-process (tools/inprocess.py, the very
`Node` code of a real match) and measures, from the ground truth (`world`, every
tick) and the referee's frames:

* `score` and `events`, the referee's command counts, as in the match JSON;
* `outside`: ticks at which the ball's centre was beyond the fence;
* `stall_s`: the longest time in which the ball moved slower than
  `STILL_SPEED` and the referee issued no command: what a spectator would
  call a stalled match;
* `stuck_s`: the longest time the ball, in play, stayed within
  `RulesParams.progress_radius` of one point: what NO_PROGRESS bounds.

`python -m arena.tools.matchfacts --seeds 20` prints one line per seed.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import msgspec

from arena.runtime.config import MatchConfig
from arena.schemas.messages import Referee, World
from arena.tools.inprocess import play_in_process

STILL_SPEED = 0.05  # [m/s] a ball slower than this is standing still
RESTARTS = ("THROWIN", "GOALKICK", "CORNER", "FREEKICK", "DROP_BALL", "PENALTY")


@dataclass(frozen=True)
class MatchFacts:
    seed: int
    score: tuple[int, int]
    events: dict[str, int]
    ticks: int  # world frames seen (ticks 0..total)
    outside: int  # ticks with the ball beyond the fence
    stall_s: float  # [s]
    stuck_s: float  # [s]


def match_facts(cfg: MatchConfig) -> MatchFacts:
    summaries, frames = play_in_process(cfg, watch=("world", "referee"))
    worlds = [msgspec.msgpack.decode(raw, type=World) for raw in frames["world"]]
    referee = {r.tick: r for r in (msgspec.msgpack.decode(raw, type=Referee) for raw in frames["referee"])}
    f, radius, dt = cfg.field, cfg.rules.progress_radius, cfg.timing.dt
    fence_x, fence_y = f.length / 2 + f.runoff, f.width / 2 + f.runoff
    outside = stall = stall_max = stuck = stuck_max = 0
    playing = False
    anchor: tuple[float, float] | None = None
    for w in worlds:
        ref = referee.get(w.tick)
        if ref is not None:
            playing = ref.command == "START"
        if abs(w.ball_x) > fence_x or abs(w.ball_y) > fence_y:
            outside += 1
        moving = math.hypot(w.ball_vx, w.ball_vy) >= STILL_SPEED
        stall = 0 if moving or (ref is not None and ref.commands) else stall + 1
        stall_max = max(stall_max, stall)
        if not playing or anchor is None or math.hypot(w.ball_x - anchor[0], w.ball_y - anchor[1]) > radius:
            anchor, stuck = (w.ball_x, w.ball_y), 0
        else:
            stuck += 1
            stuck_max = max(stuck_max, stuck)
    extra = summaries["referee"].extra
    return MatchFacts(
        seed=cfg.seed,
        score=tuple(extra["score"]),
        events=dict(extra["events"]),
        ticks=len(worlds),
        outside=outside,
        stall_s=stall_max * dt,
        stuck_s=stuck_max * dt,
    )


def many(cfgs: list[MatchConfig], workers: int | None = None) -> list[MatchFacts]:
    """`match_facts` of every configuration, in worker processes (spawned: no fork of threads)."""
    workers = workers or min(len(cfgs), os.cpu_count() or 1)
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        return list(pool.map(match_facts, cfgs))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--half-time", type=float, default=60.0)
    ap.add_argument("--home", default="chase")
    ap.add_argument("--away", default="chase")
    args = ap.parse_args(argv)
    t0 = time.monotonic()
    cfgs = [MatchConfig(seed=s, half_time=args.half_time, home=args.home, away=args.away) for s in range(args.seeds)]
    facts = many(cfgs)
    for m in facts:
        restarts = " ".join(f"{k} {m.events.get(k, 0)}" for k in RESTARTS if m.events.get(k))
        print(f"seed {m.seed:3d}  score {m.score[0]}:{m.score[1]}  END_GAME {m.events.get('END_GAME', 0)}  "
              f"outside {m.outside}  stall {m.stall_s:.2f} s  stuck {m.stuck_s:.2f} s  {restarts}")
    goals = [sum(m.score) for m in facts]
    print(f"{len(facts)} matches in {time.monotonic() - t0:.0f} s; goals per match {sum(goals) / len(goals):.2f} "
          f"(min {min(goals)}, max {max(goals)}); longest stall {max(m.stall_s for m in facts):.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
