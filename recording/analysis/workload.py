"""Where the metres go, and why robots are sent off: paper 2's Fig. 9 taken apart.

Paper 2 (Fig. 9 and its text) says static roles load robot 1, the attacker,
more than robot 2, the defender (ratio above 1.5), because each keeps to its
area of Fig. 5. `metres` attributes every metre each outfield robot travels,
from the ground truth of every tick, to three things at once:

* the team's mode (Fig. 6): `attacking` while the team has the ball,
  `defending` while the opponents have it, as the base station decides it
  (inputs b and b-bar) but from the truth: a team has the ball when one of its
  robots holds it, or when its robot is the nearest to the ball and within
  `POSSESSION_RADIUS` of it; a loose ball keeps the last mode (`loose` before
  anyone had it); `stopped` while the referee's command is not START;
* the Fig. 5 area the robot is in, by u = attack direction x field x:
  `defence` (u < -overlap/2: the defender's area only), `overlap`
  (|u| <= overlap/2: both), `attack` (u > overlap/2: the attackers' only);
* what it is doing, the first that applies: `carrying` (its dribbler holds
  the ball); `blocking` (its team defends and it stands on the kick line:
  within `KICK_LINE` of the segment from the ball to its own goal centre,
  nearer that goal than the ball); `chasing` (moving within `HEADING` of the
  direction to the ball); `returning` (moving within `HEADING` of the
  direction to its own goal line, -u); `advancing` (within `HEADING` of +u);
  `other`. The direction of motion is the tick's displacement.

A tick's metres are the robot's displacement since the previous world frame
(a jump of more than `TELEPORT` is the engine placing it, not travel).

`send_offs` lists every robot the referee sent off (DOUBLE_YELLOW, RED_CARD,
REPAIR_OUT) with the rule's cause and the robot's fouls, and `fouls` every
pushing foul: at the impact (the first tick of the referee period before the
STOP with the footprints in contact; speeds from the tick before it), the latency of the positions the
offender acted on (the perception latency: it saw the opponent as it was that
many ticks earlier), how much the centre-to-centre gap closed within that
latency (what it could not yet see), and the offender's and the victim's
speeds towards each other at the impact."""

from __future__ import annotations

import math

from arena.config import MatchConfig
from arena.recording.analysis.geometry import footprint_overlap
from arena.schemas.messages import Referee, World
from arena.schemas.vocabulary import SEND_OFF, TEAMS

POSSESSION_RADIUS = 0.4  # [m] a robot this close to the ball, and nearest to it, has it (IrisParams.possession_radius)
KICK_LINE = 0.5  # [m] a robot this close to the ball's line to its goal centre, goal-side, blocks it
HEADING = math.pi / 4  # [rad] moving within this of a direction is moving that way
TELEPORT = 0.5  # [m] a per-tick displacement larger than this is a placement, not travel

MODES = ("attacking", "defending", "loose", "stopped")
AREAS = ("defence", "overlap", "attack")
ACTIVITIES = ("carrying", "blocking", "chasing", "returning", "advancing", "other")


def _activity(
    rb, move: tuple[float, float], team_mode: str, ball: tuple[float, float], own_x: float, attack: int
) -> str:
    """What robot `rb` is doing while it moves by `move` [m] (the tick's displacement, or its velocity)."""
    if rb.has_ball:
        return "carrying"
    bx, by = ball
    if team_mode == "defending":
        sx, sy = own_x - bx, -by  # the kick line: ball -> own goal centre
        seg2 = sx * sx + sy * sy
        if seg2 > 1e-9:
            t = ((rb.x - bx) * sx + (rb.y - by) * sy) / seg2
            if 0.0 < t <= 1.0 and math.hypot(bx + t * sx - rb.x, by + t * sy - rb.y) <= KICK_LINE:
                return "blocking"
    mx, my = move
    speed = math.hypot(mx, my)
    if speed <= 0.0:
        return "other"
    cos_h = math.cos(HEADING)
    dx, dy = bx - rb.x, by - rb.y
    d = math.hypot(dx, dy)
    if d > 1e-6 and (mx * dx + my * dy) / (speed * d) >= cos_h:
        return "chasing"
    along = attack * mx / speed
    if along <= -cos_h:
        return "returning"
    if along >= cos_h:
        return "advancing"
    return "other"


def metres(cfg: MatchConfig, worlds: list[World], referee: dict[int, Referee]) -> dict[str, dict[str, float]]:
    """{"a/1": {"total": m, "defending/defence/blocking": m, ...}} for every outfield robot."""
    half_len, edge = cfg.field.length / 2, 0.5  # Fig. 5: the 1 m overlap is centred on the centre line
    out: dict[str, dict[str, float]] = {f"{t}/{n}": {"total": 0.0} for t in TEAMS for n in range(1, cfg.robots)}
    playing, attack_a, have = False, 1, ""
    prev: dict[tuple[str, int], tuple[float, float]] = {}
    for w in worlds:
        ref = referee.get(w.tick)
        if ref is not None:
            playing = ref.command == "START"
            attack_a = ref.attack_dir_a
            for c in ref.commands:
                if c.team in TEAMS and c.name not in SEND_OFF and c.name != "GOAL":
                    have = c.team  # a set piece gives the ball to one side (b for it, b-bar for the other)
        holder = next((rb.team for rb in w.robots if rb.has_ball), "")
        if holder:
            have = holder
        elif playing:
            near = min(w.robots, key=lambda rb: math.hypot(rb.x - w.ball_x, rb.y - w.ball_y), default=None)
            if near is not None and math.hypot(near.x - w.ball_x, near.y - w.ball_y) < POSSESSION_RADIUS:
                have = near.team
        for rb in w.robots:
            key = (rb.team, rb.robot)
            last = prev.get(key)
            prev[key] = (rb.x, rb.y)
            if rb.robot == 0 or last is None:
                continue
            step = math.hypot(rb.x - last[0], rb.y - last[1])
            if step <= 0.0 or step > TELEPORT:
                continue
            attack = attack_a if rb.team == "a" else -attack_a
            mode = (
                "stopped" if not playing else "loose" if not have else "attacking" if have == rb.team else "defending"
            )
            u = attack * rb.x
            area = "defence" if u < -edge else "attack" if u > edge else "overlap"
            move = (rb.x - last[0], rb.y - last[1])
            act = _activity(rb, move, mode, (w.ball_x, w.ball_y), -attack * half_len, attack)
            row = out[f"{rb.team}/{rb.robot}"]
            row["total"] += step
            cell = f"{mode}/{area}/{act}"
            row[cell] = row.get(cell, 0.0) + step
    return {k: {c: round(v, 2) for c, v in row.items()} for k, row in out.items()}


def marginal(row: dict[str, float], axis: int) -> dict[str, float]:
    """A robot's metres by mode (axis 0), area (1) or activity (2), from the cells of `metres`."""
    out: dict[str, float] = {}
    for cell, m in row.items():
        if cell != "total":
            k = cell.split("/")[axis]
            out[k] = out.get(k, 0.0) + m
    return out


def _impact(by_tick: dict[int, World], team: str, robot: int, tick: int, period: int, half: float):
    """(tick, victim's team, victim's number) for a pushing foul reported at referee tick `tick`: the first
    tick of the period before it at which the offender touches an opponent (the nearest one), else None."""
    for k in range(tick - period, tick + 1):
        w = by_tick.get(k)
        if w is None:
            continue
        me = next((rb for rb in w.robots if rb.team == team and rb.robot == robot), None)
        if me is None:
            continue
        others = [rb for rb in w.robots if rb.team != team]
        victim = min(others, key=lambda rb: math.hypot(rb.x - me.x, rb.y - me.y), default=None)
        if victim is None:
            continue
        touching = footprint_overlap((me.x, me.y, me.theta), (victim.x, victim.y, victim.theta), half) > -0.02
        if touching:
            return k, victim.team, victim.robot
    return None


def _robot(w: World, team: str, n: int):
    return next(rb for rb in w.robots if rb.team == team and rb.robot == n)


def fouls(cfg: MatchConfig, worlds: list[World], referee: dict[int, Referee], extra: dict) -> list[dict]:
    """Every pushing foul: tick, team, robot, and at its impact the latency, what it hid, and what the
    offender was doing (`_activity`; the team defends if the victim holds the ball)."""
    by_tick = {w.tick: w for w in worlds}
    attack_a, a = {}, 1
    for w in worlds:
        r = referee.get(w.tick)
        a = r.attack_dir_a if r is not None else a
        attack_a[w.tick] = a
    lat, dt, half = cfg.timing.perception_latency, cfg.timing.dt, cfg.robot.size / 2
    out = []
    for e in extra.get("log", []):
        cause = e.get("cause", "")
        if e.get("command") != "STOP" or not cause.startswith("foul_pushing "):
            continue
        team, _, n = cause.split(" ", 1)[1].partition("/")
        row = {"tick": e["tick"], "team": team, "robot": int(n), "latency_ms": round(lat * dt * 1000)}
        hit = _impact(by_tick, team, int(n), e["tick"], cfg.timing.referee_period + 1, half)
        if hit is not None and hit[0] - 1 - lat in by_tick:
            k, vt, vn = hit
            before, late = by_tick[k - 1], by_tick[k - 1 - lat]  # just before the impact, and L ticks earlier
            me, victim = _robot(before, team, int(n)), _robot(before, vt, vn)
            me_l, victim_l = _robot(late, team, int(n)), _robot(late, vt, vn)
            gap = math.hypot(victim.x - me.x, victim.y - me.y)
            ex, ey = (victim.x - me.x) / gap, (victim.y - me.y) / gap
            attack = (1 if team == "a" else -1) * attack_a.get(k, 1)
            mode = "attacking" if me.has_ball else "defending" if victim.has_ball else "loose"
            own_x = -attack * cfg.field.length / 2
            act = _activity(me, (me.vx, me.vy), mode, (before.ball_x, before.ball_y), own_x, attack)
            row |= {
                "victim": f"{vt}/{vn}",
                "activity": act,
                "unseen_closing_m": round(math.hypot(victim_l.x - me_l.x, victim_l.y - me_l.y) - gap, 3),
                "offender_speed": round(me.vx * ex + me.vy * ey, 2),  # [m/s] towards the victim
                "victim_speed": round(-(victim.vx * ex + victim.vy * ey), 2),  # [m/s] towards the offender
            }
        out.append(row)
    return out


def send_offs(extra: dict) -> list[dict]:
    """Every robot sent off: tick, card, team, robot, the score then (team a, team b), the cause of the
    card and the ticks of its fouls."""
    log = extra.get("log", [])
    out = []
    for e in log:
        if e.get("command") not in SEND_OFF or e.get("team") not in TEAMS:
            continue
        who = f"{e['team']}/{e.get('robot', -1)}"
        fouled = [f["tick"] for f in log if f.get("command") == "STOP" and f.get("cause", "").endswith(" " + who)]
        goals = [g["team"] for g in log if g.get("command") == "GOAL" and g["tick"] <= e["tick"]]
        out.append(
            {"tick": e["tick"], "card": e["command"], "team": e["team"], "robot": e.get("robot", -1)}
            | {"score_then": [goals.count("a"), goals.count("b")]}
            | {"cause": e.get("cause", ""), "foul_ticks": [t for t in fouled if t <= e["tick"]]}
        )
    return out
