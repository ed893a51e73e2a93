"""How right a team's worldstates were: each one scored against the engine's ground truth.

A base station connected through the RefBox bridge sends its world model as
MSL worldstates (docs/refbox.md); the recorder keeps every valid one on
`refbox/<team>/worldstate`. Each is compared with the `world` frame of the
moment it describes: the tick at which the bridge had it, minus its `ageMs`.
Coordinates are our field frame (docs/field.md: metres, origin on the centre
spot, x towards the goal team a attacks in the first half, theta from +x).

* robots: a worldstate robot `id` is our robot number; per robot the position
  error [m] and the heading error [rad, wrapped to (-pi, pi], absolute];
* ball: the most confident ball against the true ball, on the ground plane
  [m]; a worldstate with no ball counts as not seen;
* obstacles: the opponents are the true obstacles. Recall: the share of
  opponents with a reported obstacle within `MATCH_RADIUS`; precision: the
  share of reported obstacles within `MATCH_RADIUS` of an opponent (summed
  over all worldstates, then divided);
* ageMs as sent.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence

import numpy as np

from arena.navigation.frames import wrap_angle
from arena.runtime.stats import percentile
from arena.schemas.messages import World, Worldstate

MATCH_RADIUS = 0.5  # [m] an obstacle within this of an opponent is a hit


def _stats(values: list[float]) -> dict[str, float]:
    if not values:
        return {"n": 0, "mean": 0.0, "p95": 0.0, "max": 0.0}
    return {
        "n": len(values),
        "mean": round(sum(values) / len(values), 4),
        "p95": round(percentile(values, 95), 4),
        "max": round(float(max(values)), 4),
    }


def _xy(v) -> tuple[float, float] | None:
    """The first two numbers of a worldstate vector, or None when absent or not numbers."""
    if not isinstance(v, list) or len(v) < 2:
        return None
    x, y = v[0], v[1]
    if type(x) not in (int, float) or type(y) not in (int, float) or not (math.isfinite(x) and math.isfinite(y)):
        return None
    return float(x), float(y)


def score_team(team: str, worldstates: Sequence[Worldstate], worlds: Sequence[World], dt: float) -> dict:
    """The accuracy of one team's worldstates (see the module docstring)."""
    by_tick = {w.tick: w for w in worlds}
    ticks = sorted(by_tick)
    pos: dict[int, list[float]] = {}
    head: dict[int, list[float]] = {}
    ball_err: list[float] = []
    ages: list[float] = []
    ball_missing = unmatched = 0
    opp_total = opp_found = obs_total = obs_hit = 0
    scored = 0
    for ws in worldstates:
        try:
            doc = json.loads(ws.json)
        except ValueError:
            continue
        ages.append(ws.age_ms)
        want = max(0, ws.tick - round(ws.age_ms / 1000.0 / dt))
        if not ticks:
            break
        i = min(np.searchsorted(ticks, want), len(ticks) - 1)
        w = by_tick[ticks[i]]
        scored += 1
        truth = {rb.robot: rb for rb in w.robots if rb.team == team}
        for r in doc.get("robots", []):
            if not isinstance(r, dict):
                continue
            rid, pose = r.get("id"), r.get("pose")
            xy = _xy(pose)
            gt = truth.get(rid) if type(rid) is int else None
            if gt is None or xy is None:
                unmatched += 1
                continue
            pos.setdefault(rid, []).append(math.hypot(xy[0] - gt.x, xy[1] - gt.y))
            if len(pose) >= 3 and type(pose[2]) in (int, float) and math.isfinite(pose[2]):
                head.setdefault(rid, []).append(abs(wrap_angle(float(pose[2]) - gt.theta)))
        balls = [b for b in doc.get("balls", []) if isinstance(b, dict) and _xy(b.get("position"))]
        if balls:
            best = max(balls, key=lambda b: b.get("confidence", 0) if type(b.get("confidence")) in (int, float) else 0)
            bx, by = _xy(best["position"])
            ball_err.append(math.hypot(bx - w.ball_x, by - w.ball_y))
        else:
            ball_missing += 1
        opponents = [(rb.x, rb.y) for rb in w.robots if rb.team != team]
        reported = [xy for o in doc.get("obstacles", []) if isinstance(o, dict) and (xy := _xy(o.get("position")))]
        opp_total += len(opponents)
        obs_total += len(reported)
        opp_found += sum(
            1 for ox, oy in opponents if any(math.hypot(x - ox, y - oy) <= MATCH_RADIUS for x, y in reported)
        )
        obs_hit += sum(
            1 for x, y in reported if any(math.hypot(x - ox, y - oy) <= MATCH_RADIUS for ox, oy in opponents)
        )
    return {
        "team": team,
        "worldstates": len(worldstates),
        "scored": scored,
        "robots": {str(n): {"position_m": _stats(pos[n]), "heading_rad": _stats(head.get(n, []))} for n in sorted(pos)},
        "unmatched_robots": unmatched,
        "ball_m": _stats(ball_err),
        "ball_missing": ball_missing,
        "obstacles": {
            "recall": round(opp_found / opp_total, 4) if opp_total else None,
            "precision": round(obs_hit / obs_total, 4) if obs_total else None,
            "opponents": opp_total,
            "reported": obs_total,
            "radius_m": MATCH_RADIUS,
        },
        "age_ms": _stats(ages),
    }


def score(worldstates: dict[str, Sequence[Worldstate]], worlds: Sequence[World], dt: float) -> dict[str, dict]:
    """Per team that sent any worldstate: `score_team`."""
    return {team: score_team(team, ws, worlds, dt) for team, ws in sorted(worldstates.items()) if ws}
