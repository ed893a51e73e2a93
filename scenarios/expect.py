"""Expectations: what must come true in a scenario run, each judged on the run's trace.

One small function per kind, registered in `KINDS` (docs/scenarios.md lists
them). Each judges its window `[from, until]` (seconds; `within` is a
shorthand for `until`) of the `Trace`: the ground-truth `world` frames (every
tick), the referee's commands and the processes' digests. A judgement is
`(passed, tick, detail)`: the tick is where it failed (the first offending
tick of a "never" kind, the window's last tick of a "happens" kind).

An expectation with `when` (a condition as a step's) measures its window from
the first tick at which the condition holds on the trace; if it never holds,
the expectation fails there."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from arena.scenarios.bounds import check_region
from arena.schemas.messages import BallEvent, RefCommand, World
from arena.schemas.vocabulary import REF_COMMANDS, TEAMS

EVENT_KINDS = (
    "TOUCH",
    "GOAL",
    "GOAL_LINE",
    "TOUCH_LINE",
    "NO_PROGRESS",
    "FOUL_PUSHING",
    "FOUL_DRIBBLING",
    "ROBOT_DEAD",
    "ROBOT_STUCK",
)


@dataclass
class Trace:
    """What a run leaves to judge: frames by tick, commands in order, digests by process."""

    dt: float
    worlds: list[World]
    commands: list[RefCommand]
    digests: dict[str, str] = field(default_factory=dict)
    fence: tuple[float, float] = (7.0, 5.0)  # [m] half length and half width inside the fence: beyond is parked
    events: list[BallEvent] = field(default_factory=list)  # the engine's, in order
    scores: list[tuple[int, int, int]] = field(default_factory=list)  # (tick, goals of a, of b) per referee frame

    def window(self, e, time_limit: float, origin: int = 0) -> tuple[int, int]:
        until = e.within if e.within is not None else (e.until if e.until is not None else None)
        last = int(round(time_limit / self.dt))  # the run's end (a run judged mid-way has not reached it)
        hi = last if until is None else min(last, origin + int(round(until / self.dt)))
        return origin + int(round(e.from_ / self.dt)), hi

    def trigger(self, when) -> int | None:
        """The first tick at which the condition `when` holds on the trace (the referee's commands so far)."""
        seen: set[str] = set()
        commands = iter(self.commands)
        pending = next(commands, None)
        for w in self.worlds:
            while pending is not None and pending.tick <= w.tick:
                seen.add(pending.name)
                pending = next(commands, None)
            if holds(when, w, seen):
                return w.tick
        return None

    def frames(self, lo: int, hi: int) -> list[World]:
        return [w for w in self.worlds if lo <= w.tick <= hi]


Judgement = tuple[bool, int, str]


def _robot(text: str) -> tuple[str, int]:
    team, n = text.split("/")
    return team, int(n)


def _pose(w: World, team: str, n: int) -> tuple[float, float] | None:
    for r in w.robots:
        if r.team == team and r.robot == n:
            return r.x, r.y
    return None


def holds(c, w: World, seen: set[str]) -> bool:
    """A step's condition (scenarios/model.py `When`) on one world frame; `seen`: the commands given so far."""
    if c.ball_in is not None and not _in(c.ball_in, w.ball_x, w.ball_y):
        return False
    if c.robot_in is not None:
        p = _pose(w, *_robot(c.robot))
        if p is None or not _in(c.robot_in, *p):
            return False
    if c.command and c.command not in seen:
        return False
    return not c.possession or any(r.has_ball and r.team == c.possession for r in w.robots)


def _in(region: list[float], x: float, y: float) -> bool:
    x0, y0, x1, y1 = region
    return min(x0, x1) <= x <= max(x0, x1) and min(y0, y1) <= y <= max(y0, y1)


def _command_matches(c: RefCommand, e) -> bool:
    if c.name != e.command or (e.team and c.team != e.team):
        return False
    if e.robot and (c.team, c.robot) != _robot(e.robot):
        return False
    return e.region is None or _in(e.region, c.x, c.y)


# ------------------------------------------------------------------- the kinds
def happens(seen: Callable[[World], bool], what: str) -> Callable:
    def judge(e, t: Trace, lo: int, hi: int) -> Judgement:
        for w in t.frames(lo, hi):
            if seen(e, w):
                return True, w.tick, f"{what} at tick {w.tick}"
        return False, hi, f"{what} never happened in ticks {lo}..{hi}"

    return judge


def never(seen: Callable[[World], bool], what: str) -> Callable:
    def judge(e, t: Trace, lo: int, hi: int) -> Judgement:
        for w in t.frames(lo, hi):
            if seen(e, w):
                return False, w.tick, f"{what} at tick {w.tick}"
        return True, hi, f"no {what} in ticks {lo}..{hi}"

    return judge


def _ball_in(e, w: World) -> bool:
    return _in(e.region, w.ball_x, w.ball_y)


def _robot_in(e, w: World) -> bool:
    p = _pose(w, *_robot(e.robot))
    return p is not None and _in(e.region, *p)


def _possession(e, w: World) -> bool:
    return any(r.has_ball and r.team == e.team for r in w.robots)


def command(e, t: Trace, lo: int, hi: int) -> Judgement:
    for c in t.commands:
        if lo <= c.tick <= hi and _command_matches(c, e):
            return True, c.tick, f"{c.name} {c.team} at ({c.x:.2f}, {c.y:.2f}) at tick {c.tick}"
    seen = [f"{c.name} {c.team} at ({c.x:.2f}, {c.y:.2f}) at tick {c.tick}" for c in t.commands if c.name == e.command]
    return False, hi, f"no such {e.command} in ticks {lo}..{hi}" + (f" (seen: {'; '.join(seen[:3])})" if seen else "")


def never_command(e, t: Trace, lo: int, hi: int) -> Judgement:
    for c in t.commands:
        if lo <= c.tick <= hi and _command_matches(c, e):
            return False, c.tick, f"{c.name} {c.team} at tick {c.tick}"
    return True, hi, f"no {e.command} in ticks {lo}..{hi}"


def goal(e, t: Trace, lo: int, hi: int) -> Judgement:
    for c in t.commands:
        if lo <= c.tick <= hi and c.name == "GOAL" and c.team == e.team:
            return True, c.tick, f"goal by {e.team} at tick {c.tick}"
    return False, hi, f"no goal by {e.team} in ticks {lo}..{hi}"


def min_distance(e, t: Trace, lo: int, hi: int) -> Judgement:
    wanted = {_robot(r) for r in e.robots}
    hx, hy = t.fence
    for w in t.frames(lo, hi):
        on = [r for r in w.robots if abs(r.x) < hx and abs(r.y) < hy and (not wanted or (r.team, r.robot) in wanted)]
        for i, a in enumerate(on):
            for b in on[i + 1 :]:
                d = math.hypot(a.x - b.x, a.y - b.y)
                if d < e.distance:
                    return False, w.tick, f"{a.team}/{a.robot} and {b.team}/{b.robot} {d:.2f} m apart at tick {w.tick}"
    return True, hi, f"every pair at least {e.distance} m apart"


def not_stuck(e, t: Trace, lo: int, hi: int) -> Judgement:
    """No robot on the field stays within `radius` of one point for longer than `seconds`."""
    wanted = {_robot(r) for r in e.robots}
    limit = int(round(e.seconds / t.dt))
    anchor: dict[tuple[str, int], tuple[float, float, int]] = {}
    hx, hy = t.fence
    for w in t.frames(lo, hi):
        for r in w.robots:
            key = (r.team, r.robot)
            if (wanted and key not in wanted) or abs(r.x) >= hx or abs(r.y) >= hy:
                continue
            ax, ay, since = anchor.get(key, (r.x, r.y, w.tick))
            if math.hypot(r.x - ax, r.y - ay) > e.radius:
                anchor[key] = (r.x, r.y, w.tick)
            elif w.tick - since > limit:
                return False, w.tick, f"{r.team}/{r.robot} within {e.radius} m since tick {since}"
            else:
                anchor[key] = (ax, ay, since)
    return True, hi, f"no robot still for over {e.seconds} s"


def digest(e, t: Trace, lo: int, hi: int) -> Judgement:
    got = t.digests.get(e.process, "")
    ok = bool(got) and got.startswith(e.digest.lower())
    return ok, hi, f"{e.process} digest {got[:16] or 'missing'}"


def _fast(e, w: World) -> bool:
    return math.sqrt(w.ball_vx**2 + w.ball_vy**2 + w.ball_vz**2) > e.speed


def _event_matches(ev: BallEvent, e) -> bool:
    if ev.kind != e.event or (e.team and ev.team != e.team):
        return False
    return not e.robot or (ev.team, ev.robot) == _robot(e.robot)


def event(e, t: Trace, lo: int, hi: int) -> Judgement:
    for ev in t.events:
        if lo <= ev.tick <= hi and _event_matches(ev, e):
            return True, ev.tick, f"{ev.kind} {ev.team}/{ev.robot} at ({ev.x:.2f}, {ev.y:.2f}) at tick {ev.tick}"
    return False, hi, f"no such {e.event} in ticks {lo}..{hi}"


def never_event(e, t: Trace, lo: int, hi: int) -> Judgement:
    for ev in t.events:
        if lo <= ev.tick <= hi and _event_matches(ev, e):
            return False, ev.tick, f"{ev.kind} {ev.team}/{ev.robot} at tick {ev.tick}"
    return True, hi, f"no {e.event} in ticks {lo}..{hi}"


def last_touch(e, t: Trace, lo: int, hi: int) -> Judgement:
    """At the window's last tick, the last robot to touch the ball is of `team` (and is `robot`, if given)."""
    frames = t.frames(lo, hi)
    if not frames:
        return False, hi, f"no frame in ticks {lo}..{hi}"
    w = frames[-1]
    who = f"{w.last_team}/{w.last_robot}" if w.last_team else "nobody"
    ok = (not e.team or w.last_team == e.team) and (not e.robot or (w.last_team, w.last_robot) == _robot(e.robot))
    return ok, w.tick, f"last touched by {who} at tick {w.tick}"


def score(e, t: Trace, lo: int, hi: int) -> Judgement:
    """The score at the window's last tick (by default the run's end) is `score`."""
    got = (0, 0)
    for tick, a, b in t.scores:
        if tick > hi:
            break
        got = (a, b)
    return list(got) == list(e.score), hi, f"score {got[0]}:{got[1]} at tick {hi}"


Judge = Callable[..., Judgement]
KINDS: dict[str, tuple[tuple[str, ...], Judge]] = {
    # kind: (the keys it needs, the judge)
    "goal": (("team",), goal),
    "ball_in": (("region",), happens(_ball_in, "ball in the region")),
    "ball_never_in": (("region",), never(_ball_in, "ball in the region")),
    "robot_in": (("robot", "region"), happens(_robot_in, "robot in the region")),
    "robot_never_in": (("robot", "region"), never(_robot_in, "robot in the region")),
    "command": (("command",), command),
    "never_command": (("command",), never_command),
    "possession": (("team",), happens(_possession, "possession")),
    "min_distance": (("distance",), min_distance),
    "not_stuck": (("seconds",), not_stuck),
    "digest": (("process", "digest"), digest),
    "ball_speed": (("speed",), happens(_fast, "ball faster than the speed")),
    "ball_never_faster": (("speed",), never(_fast, "ball faster than the speed")),
    "last_touch": ((), last_touch),
    "score": (("score",), score),
    "event": (("event",), event),
    "never_event": (("event",), never_event),
}


def check_expect(e, robots: int, where: str) -> None:
    """Raise ValueError naming the key if expectation `e` cannot be judged."""
    if e.kind not in KINDS:
        raise ValueError(f"{where}.kind: {e.kind!r} is not one of {', '.join(KINDS)}")
    for key in KINDS[e.kind][0]:
        if not getattr(e, key):
            raise ValueError(f"{where}.{key}: the kind {e.kind} needs it")
    check_values(e, where)
    if e.team and e.team not in TEAMS:
        raise ValueError(f"{where}.team: {e.team!r} (a or b)")
    if e.command and e.command not in REF_COMMANDS:
        raise ValueError(f"{where}.command: {e.command!r} is not an MSL RefBox command")
    if e.region is not None:
        check_region(e.region, f"{where}.region")
    for key, r in [("robot", e.robot)] + [(f"robots[{i}]", r) for i, r in enumerate(e.robots)]:
        if r:
            parts = r.split("/")
            if len(parts) != 2 or parts[0] not in TEAMS or not parts[1].isdigit() or int(parts[1]) >= robots:
                raise ValueError(f"{where}.{key}: {r!r} is not a robot of this match (a/0 .. b/{robots - 1})")
    for key in ("within", "until"):
        v = getattr(e, key)
        if v is not None and not (math.isfinite(v) and v > 0):
            raise ValueError(f"{where}.{key}: a positive number of seconds, got {v}")
    if not (math.isfinite(e.from_) and e.from_ >= 0):
        raise ValueError(f"{where}.from: seconds >= 0, got {e.from_}")


def check_values(e, where: str) -> None:
    """The keys of the newer kinds, and every number in range."""
    if e.kind == "last_touch" and not (e.team or e.robot):
        raise ValueError(f"{where}.team: the kind last_touch needs a team or a robot")
    if e.event and e.event not in EVENT_KINDS:
        raise ValueError(f"{where}.event: {e.event!r} is not one of {', '.join(EVENT_KINDS)}")
    if e.score is not None and (len(e.score) != 2 or not all(0 <= v <= 999 for v in e.score)):
        raise ValueError(f"{where}.score: [goals of a, goals of b], got {e.score}")
    if not (math.isfinite(e.speed) and 0 <= e.speed <= 100):
        raise ValueError(f"{where}.speed: [m/s] in [0, 100], got {e.speed}")
    for key in ("distance", "seconds", "radius"):
        v = getattr(e, key)
        if not (math.isfinite(v) and 0 <= v <= 1000):
            raise ValueError(f"{where}.{key}: a number in [0, 1000], got {v}")


def judge(e, trace: Trace, time_limit: float) -> Judgement:
    origin = 0
    if e.when is not None:
        found = trace.trigger(e.when)
        if found is None:
            last = trace.worlds[-1].tick if trace.worlds else 0
            return False, last, "its `when` never held"
        origin = found
    lo, hi = trace.window(e, time_limit, origin)
    return KINDS[e.kind][1](e, trace, lo, hi)
