"""The review of a recorded match: score, goals, restarts, possession,
distances, link statistics, per-process timing, and the match facts
(facts.py) of the same World/Referee streams.

Possession and distance come from the ground-truth `world` frames: a frame
counts for the team whose robot holds the ball on its dribbler, else for the
team of the robot nearest the ball if it is within `POSSESSION_RADIUS`, else
for nobody (a loose ball). Distance per robot is the engine's Summary (physics
at 250 Hz, the number `arena match` reports), or the world frames when the
file has no summary."""

from __future__ import annotations

import dataclasses
import math
from collections import Counter

import msgspec

from arena.recording.analysis import worldstates
from arena.recording.analysis.facts import measure
from arena.recording.reader import Recording
from arena.runtime.stats import percentile
from arena.schemas.messages import EngineEvents, Referee, World, Worldstate
from arena.schemas.vocabulary import SET_PIECES

POSSESSION_RADIUS = 0.5  # [m] robot centre to ball centre: within this the nearest robot's team has the ball
JUMP = 0.5  # [m] a move longer than this between two world frames is a placement, not driving
WORLDSTATE_TOPICS = {t: f"refbox/{t}/worldstate" for t in ("a", "b")}  # the RefBox bridge's (docs/refbox.md)
NEEDED = frozenset({"world", "referee", "engine/events", *WORLDSTATE_TOPICS.values()})  # the channels a review reads


def spread(values: list[float]) -> dict[str, float]:
    """p50, p95, p99 and max of `values`, rounded to 3 decimals (all 0.0 for none)."""
    if not values:
        return {"p50": 0.0, "p95": 0.0, "p99": 0.0, "max": 0.0}
    return {
        "p50": round(percentile(values, 50), 3),
        "p95": round(percentile(values, 95), 3),
        "p99": round(percentile(values, 99), 3),
        "max": round(float(max(values)), 3),
    }


def _link_stats(rec: Recording) -> dict[str, dict]:
    """Per link class and per (receiving process, class): frames, drops, delay percentiles."""
    per_class: dict[str, dict] = {}
    per_process: dict[str, dict] = {}
    for name, s in rec.summaries.items():
        for cls, agg in s.links.items():
            frames, dropped = int(agg.get("frames", 0)), int(agg.get("dropped", 0))
            delays = s.delays_ms.get(cls, [])
            acc = per_class.setdefault(cls, {"frames": 0, "dropped": 0, "_d": []})
            acc["frames"] += frames
            acc["dropped"] += dropped
            acc["_d"].extend(delays)
            per_process.setdefault(name, {})[cls] = {
                "frames": frames,
                "dropped": dropped,
                "drop_percent": round(100.0 * dropped / frames, 3) if frames else 0.0,
                "delay_ms": spread(delays),
            }
    for acc in per_class.values():
        d = acc.pop("_d")
        acc["drop_percent"] = round(100.0 * acc["dropped"] / acc["frames"], 3) if acc["frames"] else 0.0
        acc["delay_ms"] = spread(d)
    return {"by_class": dict(sorted(per_class.items())), "by_process": per_process}


def faults_of(rec: Recording) -> list[dict]:
    """Processes that failed during the match, on the match's timeline.

    The engine's `ROBOT_DEAD` events (on the wire, in the file, at the engine's
    tick), then whatever else the summaries list as dead, at the tick their
    first claimant gave up.
    """
    dt = rec.cfg.timing.dt
    found: dict[str, dict] = {}
    decode = msgspec.msgpack.Decoder(EngineEvents).decode
    for payload in rec.payloads("engine/events"):
        try:
            events = decode(payload).events
        except (msgspec.DecodeError, msgspec.ValidationError):
            continue  # not an EngineEvents frame: nothing to say about it
        for e in events:
            if e.kind == "ROBOT_DEAD":
                name = f"robot/{e.team}/{e.robot}"
                found.setdefault(name, {"process": name, "tick": e.tick, "reason": "ROBOT_DEAD (the engine parked it)"})
    claims: dict[str, dict] = {}
    for s in rec.summaries.values():
        for peer in s.dead:
            tick = s.dead_at.get(peer, s.tick)
            if peer not in claims or tick < claims[peer]["tick"]:
                claims[peer] = {"process": peer, "tick": tick, "reason": f"{s.process} gave up waiting for it"}
    for peer, f in claims.items():
        found.setdefault(peer, f)  # the engine's event, on the match clock, comes first
    out = sorted(found.values(), key=lambda f: (f["tick"], f["process"]))
    for f in out:
        f["t"] = round(f["tick"] * dt, 2)
    return out


def analyse(rec: Recording) -> dict:
    """The review as one JSON-able dict."""
    cfg = rec.cfg
    dt = cfg.timing.dt
    refs: list[Referee] = rec.decoded("referee", Referee)
    worlds: list[World] = rec.decoded("world", World)
    score = [refs[-1].score_a, refs[-1].score_b] if refs else [0, 0]
    goals, restarts, commands = [], Counter(), Counter()
    for r in refs:
        for c in r.commands:
            commands[c.name] += 1
            if c.name in SET_PIECES:
                restarts[f"{c.name} {c.team}".strip()] += 1
            if c.name == "GOAL":
                goals.append(
                    {"tick": c.tick, "t": round(c.tick * dt, 2), "team": c.team, "score": [r.score_a, r.score_b]}
                )
    # possession and distance from the ground truth
    holds = Counter()
    dist: dict[str, float] = {}
    last: dict[str, tuple[float, float]] = {}
    for w in worlds:
        holder = ""
        best = POSSESSION_RADIUS
        for rb in w.robots:
            name = f"{rb.team}/{rb.robot}"
            if name in last:
                px, py = last[name]
                step = math.hypot(rb.x - px, rb.y - py)
                dist[name] = dist.get(name, 0.0) + (step if step <= JUMP else 0.0)
            last[name] = (rb.x, rb.y)
            if rb.has_ball:
                holder, best = rb.team, -1.0
            d = math.hypot(rb.x - w.ball_x, rb.y - w.ball_y)
            if d < best:
                holder, best = rb.team, d
        holds[holder or "loose"] += 1
    held = holds["a"] + holds["b"]
    possession = {
        "a": round(100.0 * holds["a"] / held, 1) if held else 0.0,
        "b": round(100.0 * holds["b"] / held, 1) if held else 0.0,
        "loose_percent_of_time": round(100.0 * holds["loose"] / len(worlds), 1) if worlds else 0.0,
    }
    engine = rec.summaries.get("engine")
    if engine is not None and engine.extra.get("distance_m"):
        distance, source = dict(engine.extra["distance_m"]), "engine summary"
    else:
        distance, source = {k: round(v, 3) for k, v in sorted(dist.items())}, "world frames"
    timing = {}
    for name in [str(p) for p in cfg.processes()]:
        s = rec.summaries.get(name)
        if s is None:
            continue
        timing[name] = {
            "tick_us_median": round(s.tick_us[0], 1) if s.tick_us else None,
            "tick_us_p95": round(s.tick_us[1], 1) if s.tick_us else None,
            "wall_s": round(s.wall_s, 3),
            "cpu_s": round(sum(s.cpu_s), 3) if s.cpu_s else None,
        }
    last_tick = worlds[-1].tick if worlds else 0
    referee = rec.summaries.get("referee")
    facts = None
    if referee is not None and "score" in referee.extra:
        facts = measure(cfg, worlds, {r.tick: r for r in refs}, referee.extra, distance)
    return {
        "file": rec.path,
        "truncated": rec.truncated,
        "truncation": rec.problem,
        "complete": rec.complete,
        "interrupted": rec.meta.get("recording", {}).get("interrupted", ""),
        "undecodable": dict(sorted(rec.undecodable.items())),
        "home": cfg.home,
        "away": cfg.away,
        "seed": cfg.seed,
        "robots": cfg.robots,
        "link": cfg.link,
        "git_revision": rec.meta.get("arena", {}).get("git_revision", "unknown"),
        "score": score,
        "ticks": last_tick,
        "sim_seconds": round(last_tick * dt, 3),
        "planned_ticks": cfg.total_ticks,
        "planned_sim_seconds": round(cfg.total_ticks * dt, 3),
        "goals": goals,
        "faults": faults_of(rec),
        "gaps": rec.gaps,
        "restarts": dict(sorted(restarts.items())),
        "commands": dict(sorted(commands.items())),
        "possession_percent": possession,
        "distance_m": distance,
        "distance_source": source,
        "links": _link_stats(rec),
        "timing": timing,
        "summaries": sorted(rec.summaries),
        "messages": dict(sorted(rec.counts.items())),
        "facts": dataclasses.asdict(facts) if facts is not None else None,
        "worldstate_accuracy": worldstates.score(
            {t: rec.decoded(topic, Worldstate) for t, topic in WORLDSTATE_TOPICS.items()}, worlds, dt
        ),
    }
