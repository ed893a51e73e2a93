"""`arena facts` output: one line per match, the totals per strategy, the round robin's
table, where the metres go and who was sent off, and all of it as one JSON object (`--json`,
documented in docs/strategies.md)."""

from __future__ import annotations

import dataclasses

from arena.recording.analysis import workload
from arena.recording.analysis.facts import GOAL_FAR, GOAL_NEAR, OVERLAP_DEPTH, MatchFacts
from arena.schemas.vocabulary import RESTARTS


def header(teams: bool) -> list[str]:
    """What the per-match lines' numbers are; `teams`: the second line of team play is printed."""
    out = [
        "per match: outside = ticks with the ball beyond the fence; stall = longest time the ball stood still with "
        "no referee command; stuck = longest time the ball in play stayed in one spot (what NO_PROGRESS bounds); "
        "then the restarts given"
    ]
    if teams:
        out.append(
            "  x/y = team a (home) / team b (away); saves and blocks are made by that team; contact and overlap in "
            "pair-seconds of two robots; by-fence stuck and corner in robot-seconds of the team's outfield robots; "
            "pushing = fouls given against the team"
        )
    return out


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


def totals(facts: list[MatchFacts]) -> dict[str, dict[str, float]]:
    """Totals over matches per strategy (a strategy met on both sides counts both); `summary` prints them."""
    per: dict[str, dict[str, float]] = {}
    for m in facts:
        for k, t in enumerate(m.teams):
            other = m.teams[1 - k]
            row = per.setdefault(t.strategy, dict.fromkeys(TOTALS, 0))
            row["sides"] += 1
            row["W" if t.goals > other.goals else "D" if t.goals == other.goals else "L"] += 1
            row["GF"] += t.goals
            row["GA"] += other.goals
            row["shots"] += t.shots
            row["on_target"] += t.on_target
            row["faced"] += other.on_target
            row["saves"] += t.saves
            row["blocks"] += t.blocks
            row["stuck_s"] += t.stuck_s
            row["longest_stuck_s"] = max(row["longest_stuck_s"], t.longest_stuck_s)
            row["corner_s"] += t.corner_s
            row["conceded_while_stuck"] += t.conceded_while_stuck
            row["pushing"] += t.pushing
            row["dribbling"] += t.dribbling
            for g in t.goal_shots:
                row["goals_near" if g < GOAL_NEAR else "goals_mid" if g < GOAL_FAR else "goals_far"] += 1
            if len(t.distance_m) > 2:
                row["robot1_m"] += t.distance_m[1]
                row["robot2_m"] += t.distance_m[2]
    return per


# The keys of a `totals` row, in `arena facts --json` ("strategies") and docs/strategies.md.
TOTALS = (
    "sides W D L GF GA shots on_target faced saves blocks stuck_s longest_stuck_s corner_s conceded_while_stuck "
    "pushing dribbling goals_near goals_mid goals_far robot1_m robot2_m"
).split()


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
    per = totals(facts)
    out.append(
        "strategy  sides  W  D  L  GF  GA  goals/side  shots  on-target  faced  saves  blocks  "
        "stuck-s/side  longest-stuck  corner-s/side  conceded-stuck  pushing  robot1/robot2"
    )
    from arena.experiments.fixtures import short

    for s, r in sorted(per.items()):
        s = short(s)
        k = r["sides"]
        ratio = f"{r['robot1_m'] / r['robot2_m']:.2f}" if r["robot2_m"] > 0 else "-"
        out.append(
            f"{s:8s}  {k:5d} {r['W']:2d} {r['D']:2d} {r['L']:2d} {r['GF']:3d} {r['GA']:3d}  {r['GF'] / k:10.2f}  "
            f"{r['shots']:5d}  {r['on_target']:9d}  {r['faced']:5d}  {r['saves']:5d}  {r['blocks']:6d}  "
            f"{r['stuck_s'] / k:12.1f}  {r['longest_stuck_s']:13.1f}  {r['corner_s'] / k:13.1f}  "
            f"{r['conceded_while_stuck']:14d}  "
            f"{r['pushing']:7d}  {ratio:>13s}"
        )
    out.append(
        f"goals by strike distance to the goal centre (< {GOAL_NEAR:.1f} m / < {GOAL_FAR:.1f} m / farther"
        " / not from a detected on-target shot):"
    )
    for s, r in sorted(per.items()):
        near, mid, far = r["goals_near"], r["goals_mid"], r["goals_far"]
        out.append(f"  {short(s):8s} scored {near:3d} / {mid:3d} / {far:3d} / {r['GF'] - near - mid - far:3d}")
    contact = sum(m.contact_s for m in facts) / n
    overlap = sum(m.overlap_s for m in facts) / n
    deepest = max(m.max_overlap_m for m in facts)
    out.append(
        f"robot-robot contact {contact:.1f} pair-s per match; overlap > {OVERLAP_DEPTH * 100:.0f} cm "
        f"{overlap:.2f} pair-s per match; deepest overlap {deepest * 100:.1f} cm"
    )
    return out + workload_lines(facts)


def workloads(facts: list[MatchFacts]) -> dict[str, dict[str, dict[str, float]]]:
    """Per strategy, per outfield robot ("robot1", ...), its metres per match in each cell of
    `workload.metres` (team mode / Fig. 5 area / activity) and in total, over every side it played."""
    sums: dict[str, dict[str, dict[str, float]]] = {}
    sides: dict[str, int] = {}
    for m in facts:
        for t, team in zip("ab", m.teams):
            sides[team.strategy] = sides.get(team.strategy, 0) + 1
            per = sums.setdefault(team.strategy, {})
            for key, row in m.metres.items():
                if key.startswith(t + "/"):
                    acc = per.setdefault("robot" + key.split("/")[1], {})
                    for cell, v in row.items():
                        acc[cell] = acc.get(cell, 0.0) + v
    return {
        s: {r: {c: round(v / sides[s], 1) for c, v in sorted(row.items())} for r, row in sorted(per.items())}
        for s, per in sorted(sums.items())
    }


def workload_lines(facts: list[MatchFacts]) -> list[str]:
    """Where each outfield robot's metres go (per match, per strategy), every send-off and the pushing fouls."""
    from arena.experiments.fixtures import short

    out = ["metres per match by team mode | Fig. 5 area | activity (arena.recording.analysis.workload):"]
    for s, per in workloads(facts).items():
        for r, row in per.items():
            parts = []
            for axis, names in enumerate((workload.MODES, workload.AREAS, workload.ACTIVITIES)):
                m = workload.marginal(row, axis)
                parts.append(" ".join(f"{k} {m[k]:.0f}" for k in names if m.get(k, 0.0) >= 0.5))
            out.append(f"  {short(s):3s} robot {r[5:]}  {row.get('total', 0.0):6.1f} m | " + " | ".join(parts))
    pushes = [f for m in facts for f in m.pushing_fouls]
    hit = [f for f in pushes if "unseen_closing_m" in f]
    if pushes:
        mean = (lambda k: sum(f[k] for f in hit) / len(hit)) if hit else (lambda k: float("nan"))
        out.append(
            f"pushing fouls {len(pushes)}: acted on positions {pushes[0]['latency_ms']} ms old; at the impact "
            f"(means of {len(hit)}) the gap closed {mean('unseen_closing_m'):.3f} m within that latency, "
            f"offender {mean('offender_speed'):.2f} m/s and victim {mean('victim_speed'):.2f} m/s towards each other"
        )
        doing: dict[str, int] = {}
        for f in hit:
            doing[f["activity"]] = doing.get(f["activity"], 0) + 1
        out.append(
            "  the offender was " + ", ".join(f"{k} {v}" for k, v in sorted(doing.items(), key=lambda kv: -kv[1]))
        )
    offs = [(m, o) for m in facts for o in m.send_offs]
    out.append(f"send-offs {len(offs)}" + (":" if offs else ""))
    for m, o in offs:
        team = m.teams[0 if o["team"] == "a" else 1].strategy if m.teams else ""
        out.append(
            f"  seed {m.seed}: {short(team)} robot {o['robot']} ({o['team']}) {o['card']} at tick {o['tick']} "
            f"at {o['score_then'][0]}:{o['score_then'][1]} (final {m.score[0]}:{m.score[1]}), cause {o['cause']}, its fouls at ticks "
            + ", ".join(map(str, o["foul_ticks"]))
        )
    return out


def round_robin_lines(results: list, facts: list[MatchFacts], names: list[str]) -> list[str]:
    """A round robin: one line per match, then the paper's Table 2 with the Fig. 9 coverage."""
    from arena.experiments.fixtures import short
    from arena.experiments.ratings import coverage, standings

    out = [
        f"{short(r.home):3s} {m.score[0]}:{m.score[1]} {short(r.away):3s}  seed {r.seed}"
        for r, m in zip(results, facts)
    ]
    out += summary(facts)
    cover = coverage(results, names)
    out.append("team              W  D  L  GF  GA  GD   P   robot1 m  robot2 m  ratio")
    for row in standings(results, names):
        c = cover[row["team"]]
        out.append(
            f"{short(row['team']):16s} {row['W']:2d} {row['D']:2d} {row['L']:2d} {row['GF']:3d} {row['GA']:3d} "
            f"{row['GD']:3d} {row['P']:3d}   {c['robot1_m']:7.1f}  {c['robot2_m']:7.1f}  {c['ratio']}"
        )
    return out


def as_json(facts: list[MatchFacts], latency: int, seconds: float, results: list | None, names: list[str]) -> dict:
    """`arena facts --json`: every match's facts, the totals per strategy, and a round robin's table."""
    n = len(facts)
    out = {
        "perception_latency": latency,
        "matches": [dataclasses.asdict(m) for m in facts],
        "strategies": totals(facts),
        "contact_s_per_match": sum(m.contact_s for m in facts) / n,
        "overlap_s_per_match": sum(m.overlap_s for m in facts) / n,
        "deepest_overlap_m": max(m.max_overlap_m for m in facts),
        "workload": workloads(facts),
        "seconds": round(seconds, 1),
    }
    if results is not None:
        from arena.experiments.ratings import coverage, standings

        out["standings"] = standings(results, names)
        out["coverage"] = coverage(results, names)
    return out
