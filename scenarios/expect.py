"""Expectations: what must come true in a scenario run, each judged on the run's trace.

One small function per kind, registered in `KINDS` (docs/scenarios.md lists
them). Each judges its window `[from, until]` (seconds; `within` is a
shorthand for `until`) of the `Trace`: the ground-truth `world` frames (every
tick), the referee's commands and the processes' digests. A judgement is
`(passed, tick, detail)`: the tick is where it failed (the first offending
tick of a "never" kind, the window's last tick of a "happens" kind)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from arena.schemas.messages import RefCommand, World
from arena.schemas.vocabulary import REF_COMMANDS, TEAMS


@dataclass
class Trace:
    """What a run leaves to judge: frames by tick, commands in order, digests by process."""

    dt: float
    worlds: list[World]
    commands: list[RefCommand]
    digests: dict[str, str] = field(default_factory=dict)
    fence: tuple[float, float] = (7.0, 5.0)  # [m] half length and half width inside the fence: beyond is parked

    def window(self, e, time_limit: float) -> tuple[int, int]:
        until = e.within if e.within is not None else (e.until if e.until is not None else time_limit)
        return int(round(e.from_ / self.dt)), int(round(until / self.dt))

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
}


def check_expect(e, robots: int, where: str) -> None:
    """Raise ValueError naming the key if expectation `e` cannot be judged."""
    if e.kind not in KINDS:
        raise ValueError(f"{where}.kind: {e.kind!r} is not one of {', '.join(KINDS)}")
    for key in KINDS[e.kind][0]:
        if not getattr(e, key):
            raise ValueError(f"{where}.{key}: the kind {e.kind} needs it")
    if e.team and e.team not in TEAMS:
        raise ValueError(f"{where}.team: {e.team!r} (a or b)")
    if e.command and e.command not in REF_COMMANDS:
        raise ValueError(f"{where}.command: {e.command!r} is not an MSL RefBox command")
    if e.region is not None and (len(e.region) != 4 or not all(math.isfinite(v) for v in e.region)):
        raise ValueError(f"{where}.region: [x0, y0, x1, y1] in metres, got {e.region}")
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


def judge(e, trace: Trace, time_limit: float) -> Judgement:
    lo, hi = trace.window(e, time_limit)
    return KINDS[e.kind][1](e, trace, lo, hi)
