"""`arena facts` output: one line per match and the totals per strategy."""

from __future__ import annotations

from arena.recording.analysis.facts import GOAL_FAR, GOAL_NEAR, OVERLAP_DEPTH, MatchFacts
from arena.schemas.vocabulary import RESTARTS


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
