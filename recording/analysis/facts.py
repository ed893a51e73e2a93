"""Facts about a whole match: the rules at work and play that looks like soccer.

`measure` reads one match's ground truth (`world`, every tick) and the
referee's frames, from a recording (`arena review`) or from a match played in
process (`arena facts`, experiments/facts.py), and measures:

* `score` and `events`, the referee's command counts, as in the match JSON;
* `outside`: ticks at which the ball's centre was beyond the fence;
* `stall_s`: the longest time in which the ball moved slower than
  `STILL_SPEED` and the referee issued no command: what a spectator would
  call a stalled match;
* `stuck_s`: the longest time the ball, in play, stayed within
  `RulesParams.progress_radius` of one point: what NO_PROGRESS bounds.

Team play, per team in `teams` (`TeamFacts`, team a first):

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
driving through each other), `max_overlap_m` the deepest overlap seen."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from arena.config import MatchConfig
from arena.recording.analysis import workload
from arena.recording.analysis.geometry import crossing_y, footprint_overlap
from arena.schemas.messages import Referee, World
from arena.schemas.vocabulary import TEAMS, other_team

STILL_SPEED = 0.05  # [m/s] a ball slower than this is standing still

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
    # workload.py: every outfield robot's metres by team mode, Fig. 5 area and activity ("a/1": {cell: m});
    # every pushing foul at its impact; every robot sent off
    metres: dict[str, dict[str, float]] = field(default_factory=dict)
    pushing_fouls: tuple[dict, ...] = ()
    send_offs: tuple[dict, ...] = ()


def measure(  # noqa: C901, PLR0912, PLR0915 - every fact updated from one walk over the frames
    cfg: MatchConfig, worlds: list[World], referee: dict[int, Referee], extra: dict, distance: dict
) -> MatchFacts:
    f, radius, dt = cfg.field, cfg.rules.progress_radius, cfg.timing.dt
    fence_x, fence_y = f.length / 2 + f.runoff, f.width / 2 + f.runoff
    half_len, half_wid, goal_half = f.length / 2, f.width / 2, f.goal_width / 2
    half = cfg.robot.size / 2
    decel = cfg.ball.rolling_decel
    teams = TEAMS
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
        # ---- rules facts
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
            conceding = other_team(scorer)
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
                count[other_team(s["team"])]["saves" if s["touch"] == "save" else "blocks"] += 1
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
        metres=workload.metres(cfg, worlds, referee),
        pushing_fouls=tuple(workload.fouls(cfg, worlds, referee, extra)),
        send_offs=tuple(workload.send_offs(extra)),
    )
