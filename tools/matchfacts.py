"""Facts about whole matches: the rules acceptance (issue 3) and "play that looks like soccer" (issue 4).

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

Team play (issue 4), per team in `teams` (`TeamFacts`, team a first):

* `shots`: strikes (the ball's speed jumps by more than `STRIKE_DV` in one
  tick, the new last toucher is the striker) whose straight path crosses the
  goal line the team attacks within `WIDE` of a post and that roll far enough
  to get there; `on_target`: those crossing between the posts;
* the outcome of each on-target shot, followed until the next strike, a
  referee command or `SHOT_WINDOW`: `goal` (even if touched on the way), else
  the first robot of the defending team to touch it: its goalkeeper (`saves`
  of the defending team) or an outfield robot (`blocks`), else a miss;
* `pushing` and `dribbling`: the fouls the referee gave against the team;
* `stuck_s`: robot-seconds an outfield robot of the team stood stuck by the
  fence: in play, its centre within `FENCE_BAND` of a line or beyond it, and it
  moved less than `STUCK_MOVE` in the last `STUCK_WINDOW`; `longest_stuck_s` the
  longest such spell of one robot; `corner_s`: robot-seconds in play of its
  outfield robots within `CORNER_ZONE` of a field corner (in both x and y);
* `conceded_while_stuck`: goals conceded while one of its outfield robots was
  stuck (a match "decided in a corner" shows up here);
* `distance_m`: metres travelled by robots 0..n-1 (the engine's coverage
  distance, paper 2 Fig. 9);
* `goal_shots`: for each goal that came from an on-target shot, the distance
  [m] from the strike point to the goal centre (the summary sorts them into
  close range, mid range and long shots; goals not from a detected shot, e.g.
  deflections or a ball dribbled in, are the rest).

Between robots (`contact_s`, `overlap_s`, `max_overlap_m`): the footprints are
the robots' squares; `contact_s` counts pair-seconds in play with the
footprints within `CONTACT_GAP` of each other, `overlap_s` pair-seconds (at any
time) with the footprints overlapping by more than `OVERLAP_DEPTH` (robots
driving through each other), `max_overlap_m` the deepest overlap seen.

`python -m arena.tools.matchfacts --seeds 20` prints one line per seed and a
summary; `--home AD --away BS` picks the strategies. `--round-robin AD,AS,BD,BS
--legs 4` plays every pairing `legs` times, home and away alternating, and
prints the paper's Table 2 and the robot 1 / robot 2 coverage ratio (Fig. 9),
with the tournament's own table code (tools/tournament.py).
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from itertools import combinations

import msgspec

from arena.runtime.config import MatchConfig
from arena.schemas.messages import Referee, World
from arena.tools.inprocess import play_in_process

STILL_SPEED = 0.05  # [m/s] a ball slower than this is standing still
RESTARTS = ("THROWIN", "GOALKICK", "CORNER", "FREEKICK", "DROP_BALL", "PENALTY")

STRIKE_DV = 1.5  # [m/s] a jump of the ball's speed in one tick larger than this is a strike (kick or hit)
WIDE = 0.5  # [m] a strike crossing the goal line this far outside a post still counts as a shot
SHOT_WINDOW = 3.0  # [s] a shot's outcome is decided within this time
CONTACT_GAP = 0.01  # [m] footprints closer than this touch
OVERLAP_DEPTH = 0.03  # [m] footprints overlapping deeper than this: a robot drives through another
FENCE_BAND = 0.5  # [m] a robot centre within this of a line (or beyond it) is by the fence
STUCK_WINDOW = 2.0  # [s]
STUCK_MOVE = 0.25  # [m] moving less than this over STUCK_WINDOW by the fence is being stuck
CORNER_ZONE = 1.5  # [m] from a field corner in both x and y
GOAL_NEAR = 2.5  # [m] summary: a goal struck closer than this to the goal centre is a close-range goal
GOAL_FAR = 4.5  # [m] ... farther than this a long shot (the advance shooting distance)


@dataclass(frozen=True)
class TeamFacts:
    strategy: str
    goals: int = 0
    shots: int = 0
    on_target: int = 0
    saves: int = 0  # opponents' on-target shots stopped by this team's goalkeeper
    blocks: int = 0  # opponents' on-target shots stopped by this team's outfield robots
    pushing: int = 0
    dribbling: int = 0
    stuck_s: float = 0.0  # [robot-s]
    longest_stuck_s: float = 0.0  # [s]
    corner_s: float = 0.0  # [robot-s]
    conceded_while_stuck: int = 0
    distance_m: tuple[float, ...] = ()
    goal_shots: tuple[float, ...] = ()  # [m] per goal scored from an on-target shot: strike point to the goal centre


@dataclass(frozen=True)
class MatchFacts:
    seed: int
    score: tuple[int, int]
    events: dict[str, int]
    ticks: int  # world frames seen (ticks 0..total)
    outside: int  # ticks with the ball beyond the fence
    stall_s: float  # [s]
    stuck_s: float  # [s]
    teams: tuple[TeamFacts, ...] = ()
    contact_s: float = 0.0  # [pair-s]
    overlap_s: float = 0.0  # [pair-s]
    max_overlap_m: float = 0.0  # [m]
    fouls: dict[str, int] = field(default_factory=dict)


# ----------------------------------------------------------------- geometry
def footprint_overlap(a, b, half: float) -> float:
    """Overlap [m] of two squares of half side `half` (a, b: x, y, theta); negative: the gap.

    Separating-axis test over the four face normals; the result is the smallest
    penetration along them (the gap along the best separating axis when apart).
    """
    dx, dy = b[0] - a[0], b[1] - a[1]
    best = math.inf
    ca, sa, cb, sb = math.cos(a[2]), math.sin(a[2]), math.cos(b[2]), math.sin(b[2])
    for ux, uy in ((ca, sa), (-sa, ca), (cb, sb), (-sb, cb)):
        # projection radius of each square on the axis
        ra = half * (abs(ux * ca + uy * sa) + abs(-ux * sa + uy * ca))
        rb = half * (abs(ux * cb + uy * sb) + abs(-ux * sb + uy * cb))
        best = min(best, ra + rb - abs(dx * ux + dy * uy))
    return best


def crossing_y(x: float, y: float, vx: float, vy: float, line_x: float) -> float | None:
    """y [m] at which a ball at (x, y) moving with (vx, vy) crosses x = line_x; None if it moves away."""
    if vx == 0.0 or (line_x - x) * vx <= 0.0:
        return None
    return y + vy * (line_x - x) / vx


# ---------------------------------------------------------------- measuring
def match_facts(cfg: MatchConfig) -> MatchFacts:
    summaries, frames = play_in_process(cfg, watch=("world", "referee"))
    worlds = [msgspec.msgpack.decode(raw, type=World) for raw in frames["world"]]
    referee = {r.tick: r for r in (msgspec.msgpack.decode(raw, type=Referee) for raw in frames["referee"])}
    extra = summaries["referee"].extra
    return measure(cfg, worlds, referee, extra, summaries["engine"].extra.get("distance_m", {}))


def measure(
    cfg: MatchConfig, worlds: list[World], referee: dict[int, Referee], extra: dict, distance: dict
) -> MatchFacts:
    f, radius, dt = cfg.field, cfg.rules.progress_radius, cfg.timing.dt
    fence_x, fence_y = f.length / 2 + f.runoff, f.width / 2 + f.runoff
    half_len, half_wid, goal_half = f.length / 2, f.width / 2, f.goal_width / 2
    half = cfg.robot.size / 2
    decel = cfg.ball.rolling_decel
    teams = ("a", "b")
    n = cfg.robots
    window = int(round(STUCK_WINDOW / dt))
    shot_ticks = int(round(SHOT_WINDOW / dt))

    outside = stall = stall_max = stuck = stuck_max = 0
    playing = False
    attack_a = 1
    anchor: tuple[float, float] | None = None
    goal_ticks: list[tuple[int, str]] = []
    stops: list[int] = []
    for r in referee.values():
        for c in r.commands:
            if c.name == "GOAL":
                goal_ticks.append((r.tick, c.team))
            elif c.name == "STOP":
                stops.append(r.tick)
    goal_ticks.sort()
    stops.sort()

    keys = ("shots", "on_target", "saves", "blocks", "stuck", "corner", "conceded_stuck")
    count = {t: dict.fromkeys(keys, 0) for t in teams}
    longest = {t: 0 for t in teams}
    spell: dict[tuple[str, int], int] = {}
    history: dict[tuple[str, int], list[tuple[float, float]]] = {}
    stuck_now: dict[str, bool] = {t: False for t in teams}
    contact = overlap = 0
    max_overlap = 0.0
    open_shots: list[dict] = []  # on-target shots whose outcome is pending
    goal_dist: dict[str, list[float]] = {t: [] for t in teams}
    prev: World | None = None
    goal_iter = iter(goal_ticks)
    next_goal = next(goal_iter, None)
    for w in worlds:
        ref = referee.get(w.tick)
        if ref is not None:
            playing = ref.command == "START"
            attack_a = ref.attack_dir_a
            if ref.commands:
                for s in open_shots:  # a command ends every pending shot (a goal is matched below)
                    s["end"] = min(s["end"], w.tick)
        # ---- rules facts (issue 3)
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
        # ---- robots: contact and overlap between footprints
        rs = w.robots
        for i in range(len(rs)):
            ri = rs[i]
            for j in range(i + 1, len(rs)):
                rj = rs[j]
                if abs(ri.x - rj.x) > 0.7 or abs(ri.y - rj.y) > 0.7:
                    continue
                o = footprint_overlap((ri.x, ri.y, ri.theta), (rj.x, rj.y, rj.theta), half)
                if o > -CONTACT_GAP and playing:
                    contact += 1
                if o > OVERLAP_DEPTH:
                    overlap += 1
                max_overlap = max(max_overlap, o)
        # ---- stuck by the fence, corners
        for t in teams:
            stuck_now[t] = False
        for rb in rs:
            key = (rb.team, rb.robot)
            hist = history.setdefault(key, [])
            hist.append((rb.x, rb.y))
            if len(hist) > window + 1:
                del hist[0]
            if rb.robot == 0 or not playing:
                spell[key] = 0
                continue
            ax, ay = abs(rb.x), abs(rb.y)
            if ax > half_len - CORNER_ZONE and ay > half_wid - CORNER_ZONE:
                count[rb.team]["corner"] += 1
            by_fence = ax > half_len - FENCE_BAND or ay > half_wid - FENCE_BAND
            old = hist[0]
            if by_fence and len(hist) > window and math.hypot(rb.x - old[0], rb.y - old[1]) < STUCK_MOVE:
                count[rb.team]["stuck"] += 1
                spell[key] = spell.get(key, 0) + 1
                longest[rb.team] = max(longest[rb.team], spell[key])
                stuck_now[rb.team] = True
            else:
                spell[key] = 0
        while next_goal is not None and next_goal[0] <= w.tick:
            scorer = next_goal[1]
            conceding = "b" if scorer == "a" else "a"
            if stuck_now[conceding]:
                count[conceding]["conceded_stuck"] += 1
            mine = [s for s in open_shots if s["team"] == scorer and s["outcome"] == ""]
            for s in mine:
                s["outcome"] = "goal"
            if mine:  # the latest pending shot is the one that went in
                goal_dist[scorer].append(mine[-1]["dist"])
            next_goal = next(goal_iter, None)
        # ---- strikes, shots and their outcome
        if prev is not None:
            if w.last_robot >= 0 and (w.last_team, w.last_robot) != (prev.last_team, prev.last_robot):
                for s in open_shots:
                    if s["touch"] == "" and w.tick <= s["end"] and w.last_team != s["team"]:
                        s["touch"] = "save" if w.last_robot == 0 else "block"
            jump = math.hypot(w.ball_vx, w.ball_vy) - math.hypot(prev.ball_vx, prev.ball_vy)
            if playing and jump > STRIKE_DV and w.last_team in teams:
                for s in open_shots:
                    s["end"] = min(s["end"], w.tick - 1)
                t = w.last_team
                attack = attack_a if t == "a" else -attack_a
                line_x = attack * half_len
                y = crossing_y(w.ball_x, w.ball_y, w.ball_vx, w.ball_vy, line_x)
                speed = math.hypot(w.ball_vx, w.ball_vy)
                if y is not None and abs(y) < goal_half + WIDE:
                    reach = speed * speed / (2.0 * decel)
                    if reach >= math.hypot(line_x - w.ball_x, y - w.ball_y):
                        count[t]["shots"] += 1
                        if abs(y) < goal_half:
                            count[t]["on_target"] += 1
                            open_shots.append(
                                {
                                    "team": t,
                                    "end": w.tick + shot_ticks,
                                    "outcome": "",
                                    "touch": "",
                                    "dist": round(math.hypot(line_x - w.ball_x, w.ball_y), 2),
                                }
                            )
        pending = []
        for s in open_shots:
            if s["outcome"] == "" and w.tick < s["end"]:
                pending.append(s)
            elif s["outcome"] != "goal" and s["touch"]:  # touched and not in: a save or a block
                count["b" if s["team"] == "a" else "a"]["saves" if s["touch"] == "save" else "blocks"] += 1
        open_shots = pending
        prev = w

    fouls: dict[str, int] = {}
    by_team = {t: {"pushing": 0, "dribbling": 0} for t in teams}
    for e in extra.get("log", []):
        cause = e.get("cause", "")
        if cause.startswith("foul_") and e.get("command") == "STOP":
            kind, _, who = cause.partition(" ")
            fouls[kind] = fouls.get(kind, 0) + 1
            team = who.split("/")[0]
            if team in by_team:
                by_team[team]["pushing" if kind == "foul_pushing" else "dribbling"] += 1
    score = tuple(extra["score"])
    team_facts = tuple(
        TeamFacts(
            strategy=cfg.strategy_of(t),
            goals=score[k],
            shots=count[t]["shots"],
            on_target=count[t]["on_target"],
            saves=count[t]["saves"],
            blocks=count[t]["blocks"],
            pushing=by_team[t]["pushing"],
            dribbling=by_team[t]["dribbling"],
            stuck_s=round(count[t]["stuck"] * dt, 2),
            longest_stuck_s=round(longest[t] * dt, 2),
            corner_s=round(count[t]["corner"] * dt, 2),
            conceded_while_stuck=count[t]["conceded_stuck"],
            distance_m=tuple(round(distance.get(f"{t}/{i}", 0.0), 1) for i in range(n)),
            goal_shots=tuple(goal_dist[t]),
        )
        for k, t in enumerate(teams)
    )
    return MatchFacts(
        seed=cfg.seed,
        score=score,
        events=dict(extra["events"]),
        ticks=len(worlds),
        outside=outside,
        stall_s=stall_max * dt,
        stuck_s=stuck_max * dt,
        teams=team_facts,
        contact_s=round(contact * dt, 2),
        overlap_s=round(overlap * dt, 2),
        max_overlap_m=round(max_overlap, 4),
        fouls=fouls,
    )


def many(cfgs: list[MatchConfig], workers: int | None = None) -> list[MatchFacts]:
    """`match_facts` of every configuration, in worker processes (spawned: no fork of threads)."""
    workers = workers or min(len(cfgs), os.cpu_count() or 1)
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        return list(pool.map(match_facts, cfgs))


# ------------------------------------------------------------------ output
def line(m: MatchFacts) -> str:
    """One match; "x/y" is team a / team b (saves and blocks: made by that team's robots)."""
    restarts = " ".join(f"{k} {m.events.get(k, 0)}" for k in RESTARTS if m.events.get(k))
    out = (
        f"seed {m.seed:3d}  score {m.score[0]}:{m.score[1]}  END_GAME {m.events.get('END_GAME', 0)}  "
        f"outside {m.outside}  stall {m.stall_s:.2f} s  stuck {m.stuck_s:.2f} s  {restarts}"
    )
    if m.teams:
        a, b = m.teams
        out += (
            f"\n          shots {a.shots}/{b.shots} on target {a.on_target}/{b.on_target} "
            f"keeper saves {a.saves}/{b.saves} blocks {a.blocks}/{b.blocks}  "
            f"contact {m.contact_s:.1f} pair-s overlap {m.overlap_s:.2f} pair-s (max {m.max_overlap_m * 100:.1f} cm)  "
            f"by-fence stuck {a.stuck_s:.1f}/{b.stuck_s:.1f} robot-s corner {a.corner_s:.1f}/{b.corner_s:.1f} robot-s  "
            f"pushing {a.pushing}/{b.pushing}"
        )
    return out


def summary(facts: list[MatchFacts]) -> list[str]:
    """Totals over matches, per strategy (a strategy met on both sides counts both)."""
    goals = [sum(m.score) for m in facts]
    n = len(facts)
    out = [
        f"{n} matches; goals per match {sum(goals) / n:.2f} (min {min(goals)}, max {max(goals)}); "
        f"longest stall {max(m.stall_s for m in facts):.2f} s"
    ]
    if not facts[0].teams:
        return out
    per: dict[str, dict[str, float]] = {}
    for m in facts:
        for k, t in enumerate(m.teams):
            other = m.teams[1 - k]
            row = per.setdefault(
                t.strategy,
                {
                    "sides": 0,
                    "W": 0,
                    "D": 0,
                    "L": 0,
                    "GF": 0,
                    "GA": 0,
                    "shots": 0,
                    "on_target": 0,
                    "faced": 0,
                    "saves": 0,
                    "blocks": 0,
                    "stuck": 0.0,
                    "longest": 0.0,
                    "corner": 0.0,
                    "conceded_stuck": 0,
                    "pushing": 0,
                    "d1": 0.0,
                    "d2": 0.0,
                    "g_near": 0,
                    "g_mid": 0,
                    "g_far": 0,
                },
            )
            row["sides"] += 1
            row["W" if t.goals > other.goals else "D" if t.goals == other.goals else "L"] += 1
            row["GF"] += t.goals
            row["GA"] += other.goals
            row["shots"] += t.shots
            row["on_target"] += t.on_target
            row["faced"] += other.on_target
            row["saves"] += t.saves
            row["blocks"] += t.blocks
            row["stuck"] += t.stuck_s
            row["longest"] = max(row["longest"], t.longest_stuck_s)
            row["corner"] += t.corner_s
            row["conceded_stuck"] += t.conceded_while_stuck
            row["pushing"] += t.pushing
            for g in t.goal_shots:
                row["g_near" if g < GOAL_NEAR else "g_mid" if g < GOAL_FAR else "g_far"] += 1
            if len(t.distance_m) > 2:
                row["d1"] += t.distance_m[1]
                row["d2"] += t.distance_m[2]
    out.append(
        "strategy  sides  W  D  L  GF  GA  goals/side  shots  on-target  faced  saves  blocks  "
        "stuck-s/side  longest-stuck  corner-s/side  conceded-stuck  pushing  robot1/robot2"
    )
    from arena.tools.tournament import short

    for s, r in sorted(per.items()):
        s = short(s)
        k = r["sides"]
        ratio = f"{r['d1'] / r['d2']:.2f}" if r["d2"] > 0 else "-"
        out.append(
            f"{s:8s}  {k:5d} {r['W']:2d} {r['D']:2d} {r['L']:2d} {r['GF']:3d} {r['GA']:3d}  {r['GF'] / k:10.2f}  "
            f"{r['shots']:5d}  {r['on_target']:9d}  {r['faced']:5d}  {r['saves']:5d}  {r['blocks']:6d}  "
            f"{r['stuck'] / k:12.1f}  {r['longest']:13.1f}  {r['corner'] / k:13.1f}  {r['conceded_stuck']:14d}  "
            f"{r['pushing']:7d}  {ratio:>13s}"
        )
    out.append(
        f"goals by strike distance to the goal centre (< {GOAL_NEAR:.1f} m / < {GOAL_FAR:.1f} m / farther"
        " / not from a detected on-target shot):"
    )
    for s, r in sorted(per.items()):
        near, mid, far = r["g_near"], r["g_mid"], r["g_far"]
        out.append(f"  {short(s):8s} scored {near:3d} / {mid:3d} / {far:3d} / {r['GF'] - near - mid - far:3d}")
    contact = sum(m.contact_s for m in facts) / n
    overlap = sum(m.overlap_s for m in facts) / n
    deepest = max(m.max_overlap_m for m in facts)
    out.append(
        f"robot-robot contact {contact:.1f} pair-s per match; overlap > {OVERLAP_DEPTH * 100:.0f} cm "
        f"{overlap:.2f} pair-s per match; deepest overlap {deepest * 100:.1f} cm"
    )
    return out


def round_robin(
    strategies: list[str], legs: int, half_time: float, seed: int, workers: int
) -> tuple[list, list[MatchFacts]]:
    """Every pairing `legs` times, home and away alternating, in-process; returns (Results, facts)."""
    from arena.runtime import seeds
    from arena.tools.tournament import Result

    fixtures = []
    for first, second in combinations(strategies, 2):
        for leg in range(1, legs + 1):
            home, away = (first, second) if leg % 2 == 1 else (second, first)
            s = seeds.derive(seed, "tournament", first, second, leg) % (2**31)
            fixtures.append((first, second, leg, home, away, s))
    cfgs = [MatchConfig(seed=s, home=h, away=a, half_time=half_time) for _, _, _, h, a, s in fixtures]
    facts = many(cfgs, workers)
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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--half-time", type=float, default=60.0)
    ap.add_argument("--home", default="chase")
    ap.add_argument("--away", default="chase")
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--round-robin", default="", help="comma-separated strategies, e.g. AD,AS,BD,BS")
    ap.add_argument("--legs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0, help="round-robin: the tournament seed")
    args = ap.parse_args(argv)
    t0 = time.monotonic()
    if args.round_robin:
        from arena.strategies import registry
        from arena.tools.tournament import coverage, short, standings

        names = [registry.resolve_name(s) for s in args.round_robin.split(",")]
        results, facts = round_robin(names, args.legs, args.half_time, args.seed, args.workers)
        for r, m in zip(results, facts):
            print(f"{short(r.home):3s} {m.score[0]}:{m.score[1]} {short(r.away):3s}  seed {r.seed}")
        for row in summary(facts):
            print(row)
        cover = coverage(results, names)
        print("team              W  D  L  GF  GA  GD   P   robot1 m  robot2 m  ratio")
        for row in standings(results, names):
            c = cover[row["team"]]
            print(
                f"{short(row['team']):16s} {row['W']:2d} {row['D']:2d} {row['L']:2d} {row['GF']:3d} {row['GA']:3d} "
                f"{row['GD']:3d} {row['P']:3d}   {c['robot1_m']:7.1f}  {c['robot2_m']:7.1f}  {c['ratio']}"
            )
        print(f"{len(facts)} matches in {time.monotonic() - t0:.0f} s")
        return 0
    cfgs = [
        MatchConfig(seed=s, half_time=args.half_time, home=args.home, away=args.away)
        for s in range(args.first_seed, args.first_seed + args.seeds)
    ]
    facts = many(cfgs, args.workers)
    for m in facts:
        print(line(m))
    for row in summary(facts):
        print(row)
    print(f"in {time.monotonic() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
