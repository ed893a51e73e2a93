"""Set pieces: where the ball is put back, who keeps away from it, and where a
robot that did not is put.

The referee box (`referee_box.py`) takes the ball spots from here, the engine
(`engine.py`) the distance rule and the placement, the simple strategy the
distances. Everything is a pure function of positions and the configuration;
the numbers are in `RulesParams` and `FieldParams` (config/__init__.py) and
the table of rules is docs/rules.md.

Ball spots (field frame, SI units; L, W the field's length and width):

* THROWIN: on the touch line the ball crossed, at the x where it crossed,
  kept `spot_inset` from the goal lines. The 1 m run-off is where the taker
  stands (paper 2, "Soccer Field Object").
* CORNER: `corner_inset` from both lines at the corner nearest to where the
  ball went out, inside the corner arc.
* GOALKICK: the corner of the goal area on the side the ball went out.
* FREEKICK: where the foul happened, kept `spot_inset` inside the lines and
  moved out of a penalty area onto its front line (a foul by a defender in
  its own penalty area is a PENALTY instead, see docs/rules.md).
* PENALTY: the penalty mark of the defending team's goal
  (`FieldParams.penalty_mark_distance` from its goal line, on the centre
  line of the field's length axis).
* DROP_BALL: where the ball was, kept `drop_ball_inset` inside the lines.
* KICKOFF: the centre spot.

Distances while the teams position themselves (robot centre to ball spot):

* KICKOFF: the opponents of the kicking team stay outside the centre circle
  (its radius plus half a robot);
* FREEKICK, GOALKICK, THROWIN, CORNER, PENALTY: the opponents of the taking
  team keep `setpiece_distance` (>= 2 m; MSL 3 m on its bigger field);
* DROP_BALL: every robot keeps `drop_ball_distance`.

A goalkeeper (robot 0) inside its own penalty area is exempt, so that a free
kick near its goal does not pull it out. When the positioning time is over
(START) the engine moves every robot still too close to the nearest free spot
just outside the distance (`legal_spot`); the robot keeps its heading.
A penalty has its own positions (`penalty_positions`).

`Restarts` carries the referee's commands out on the engine's physics (any
`Pitch`): it stops play, pins the ball on its spot, places the robots for a
kick-off or a penalty and, at START, moves the ones still too close. The
strategies' side of a set piece (how a team positions itself for it) is
strategies/iris/setpieces.py."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from arena.config import TEAMS, MatchConfig
from arena.schemas.messages import RefCommand, Referee
from arena.schemas.vocabulary import SEND_OFF, SET_PIECES, other_team

PLACE_MARGIN = 0.05  # [m] a placed robot stands this much beyond the distance it must keep
RING_STEP = 0.5  # [m] next ring of candidate spots when a whole ring is taken
ANGLE_STEP = math.radians(5.0)  # [rad] between candidate spots on a ring
CLEARANCE = 0.05  # [m] between a placed robot's bounding circle and the others', and to the fence


def attack_dir(team: str, attack_dir_a: int) -> int:
    """+1 if `team` attacks the +x goal now, -1 for the -x goal."""
    return attack_dir_a if team == "a" else -attack_dir_a


def defender_of_goal_line(x: float, attack_dir_a: int) -> str:
    """The team whose goal line is on the side of x (the x = sign(x) * L/2 line)."""
    side = 1 if x > 0 else -1
    return "b" if side == attack_dir_a else "a"


def _clamp(v: float, lim: float) -> float:
    return max(-lim, min(lim, v))


# ----------------------------------------------------------------- ball spots
def throw_in_spot(x: float, y: float, cfg: MatchConfig) -> tuple[float, float]:
    f, r = cfg.field, cfg.rules
    return _clamp(x, f.length / 2 - r.spot_inset), math.copysign(f.width / 2, y)


def corner_spot(x: float, y: float, cfg: MatchConfig) -> tuple[float, float]:
    f, r = cfg.field, cfg.rules
    return math.copysign(f.length / 2 - r.corner_inset, x), math.copysign(f.width / 2 - r.corner_inset, y)


def goal_kick_spot(x: float, y: float, cfg: MatchConfig) -> tuple[float, float]:
    f = cfg.field
    return math.copysign(f.length / 2 - f.goal_area_depth, x), math.copysign(f.goal_area_width / 2, y)


def free_kick_spot(x: float, y: float, cfg: MatchConfig) -> tuple[float, float]:
    f, r = cfg.field, cfg.rules
    x = _clamp(x, f.length / 2 - r.spot_inset)
    y = _clamp(y, f.width / 2 - r.spot_inset)
    front = f.length / 2 - f.penalty_area_depth  # |x| of a penalty area's front line
    if abs(x) > front and abs(y) < f.penalty_area_width / 2:
        x = math.copysign(front, x)
    return x, y


def penalty_spot(defender: str, attack_dir_a: int, cfg: MatchConfig) -> tuple[float, float]:
    """The penalty mark in front of `defender`'s goal."""
    f = cfg.field
    return -attack_dir(defender, attack_dir_a) * (f.length / 2 - f.penalty_mark_distance), 0.0


def drop_ball_spot(x: float, y: float, cfg: MatchConfig) -> tuple[float, float]:
    f, inset = cfg.field, cfg.rules.drop_ball_inset
    return _clamp(x, f.length / 2 - inset), _clamp(y, f.width / 2 - inset)


# ------------------------------------------------------------------ distances
@dataclass(frozen=True)
class KeepAway:
    """The distance a restart keeps robots from the ball spot, and the teams it binds."""

    distance: float  # [m] robot centre to ball spot
    teams: tuple[str, ...]  # the teams that must keep it


def keep_away(command: str, team: str, cfg: MatchConfig) -> KeepAway | None:
    """Who keeps how far from the ball spot while `command` (for `team`) is being set up."""
    r = cfg.rules
    if command == "KICKOFF":
        return KeepAway(cfg.field.center_circle_radius + cfg.robot.size / 2, (other_team(team),))
    if command == "DROP_BALL":
        return KeepAway(r.drop_ball_distance, TEAMS)
    if command in SET_PIECES and team in TEAMS:
        return KeepAway(r.setpiece_distance, (other_team(team),))
    return None


def in_own_penalty_area(team: str, x: float, y: float, attack_dir_a: int, cfg: MatchConfig) -> bool:
    f = cfg.field
    own = -attack_dir(team, attack_dir_a)  # side of its own goal
    return own * x > f.length / 2 - f.penalty_area_depth and abs(y) < f.penalty_area_width / 2


def too_close(
    robots: list[tuple[str, int, float, float]],
    command: str,
    team: str,
    spot: tuple[float, float],
    attack_dir_a: int,
    cfg: MatchConfig,
) -> list[tuple[str, int]]:
    """(team, n) of every robot that breaks the distance rule of `command`, in the given order."""
    rule = keep_away(command, team, cfg)
    if rule is None:
        return []
    out = []
    for t, n, x, y in robots:
        if t not in rule.teams or math.hypot(x - spot[0], y - spot[1]) >= rule.distance:
            continue
        if n == 0 and in_own_penalty_area(t, x, y, attack_dir_a, cfg):
            continue
        out.append((t, n))
    return out


def legal_spot(
    x: float,
    y: float,
    spot: tuple[float, float],
    distance: float,
    others: list[tuple[float, float]],
    cfg: MatchConfig,
    accept=None,
) -> tuple[float, float]:
    """The free place nearest to (x, y) at least `distance` from `spot`.

    Candidates lie on rings around the spot (radius distance + PLACE_MARGIN,
    then RING_STEP further out), first in the robot's own direction from the
    spot, then alternately ANGLE_STEP to either side. A candidate must keep
    the robot inside the fence, out of both goals, and clear of every robot
    in `others` (bounding circles), and pass `accept(x, y)` if given.
    Deterministic; falls back to (x, y) if nothing fits (never with the
    default field).
    """
    f, size = cfg.field, cfg.robot.size
    reach = size * math.sqrt(0.5)  # [m] bounding circle radius of the square footprint
    xmax = f.length / 2 + f.runoff - reach - CLEARANCE
    ymax = f.width / 2 + f.runoff - reach - CLEARANCE
    goal_y = f.goal_width / 2 + reach + CLEARANCE
    goal_x = f.length / 2 - reach - CLEARANCE
    gap = 2 * reach + CLEARANCE
    dx, dy = x - spot[0], y - spot[1]
    if math.hypot(dx, dy) > 1e-9:
        base = math.atan2(dy, dx)
    else:
        base = math.atan2(-spot[1], -spot[0]) if math.hypot(*spot) > 1e-9 else math.pi
    steps = int(math.pi / ANGLE_STEP)
    for ring in range(8):
        radius = distance + PLACE_MARGIN + ring * RING_STEP
        for k in range(2 * steps):
            a = base + (k + 1) // 2 * ANGLE_STEP * (1 if k % 2 else -1)
            cx, cy = spot[0] + radius * math.cos(a), spot[1] + radius * math.sin(a)
            if abs(cx) > xmax or abs(cy) > ymax or (abs(cx) > goal_x and abs(cy) < goal_y):
                continue
            if all(math.hypot(cx - ox, cy - oy) >= gap for ox, oy in others) and (accept is None or accept(cx, cy)):
                return cx, cy
    return x, y


# ------------------------------------------------------------------ penalty
PENALTY_BEHIND = 0.5  # [m] the taker's centre behind the penalty mark


def penalty_positions(
    robots: list[tuple[str, int, float, float]],
    taker_team: str,
    spot: tuple[float, float],
    attack_dir_a: int,
    cfg: MatchConfig,
) -> list[tuple[str, int, float, float, float]]:
    """(team, n, x, y, theta) of every robot that must move for a penalty.

    The defending keeper (robot 0) stands on its goal line, in the middle of
    the goal, facing the field. The taker, the taking team's field robot
    nearest to the mark (its keeper if it has no other), stands
    `PENALTY_BEHIND` behind the mark facing the goal. Every other robot
    leaves the penalty area, keeps `setpiece_distance` from the mark and
    stands inside the field of play, its centre not beyond a line (MSL, as
    FIFA Law 14: "inside the field of play, outside the penalty area"), found
    by `legal_spot` with rings further out until the place is outside the area
    (and, if that place is off the field, the nearest one that is neither).
    Robots already where they may be are not in the list.
    """
    f, reach = cfg.field, cfg.robot.size * math.sqrt(0.5)
    defender = other_team(taker_team)
    side = -attack_dir(defender, attack_dir_a)  # x sign of the defended goal
    front = f.length / 2 - f.penalty_area_depth

    def in_area(x: float, y: float) -> bool:
        return side * x > front - reach and abs(y) < f.penalty_area_width / 2 + reach

    def on_field(x: float, y: float) -> bool:
        return abs(x) <= f.length / 2 and abs(y) <= f.width / 2

    pos = {(t, n): (x, y) for t, n, x, y in robots}
    takers = sorted((math.hypot(x - spot[0], y - spot[1]), n) for t, n, x, y in robots if t == taker_team and n != 0)
    taker = (taker_team, takers[0][1] if takers else 0)
    keeper = (defender, 0)
    fixed = {taker: (spot[0] - side * PENALTY_BEHIND, spot[1], 0.0 if side > 0 else math.pi)}
    if keeper in pos:
        fixed[keeper] = (side * (f.length / 2 - cfg.robot.size / 2), 0.0, math.pi if side > 0 else 0.0)
    moves = [(t, n, x, y, th) for (t, n), (x, y, th) in fixed.items() if (t, n) in pos]
    for r, (x, y, _) in fixed.items():
        pos[r] = (x, y)
    d0 = cfg.rules.setpiece_distance
    for t, n, x, y in robots:
        if (t, n) in fixed or (math.hypot(x - spot[0], y - spot[1]) >= d0 and not in_area(x, y) and on_field(x, y)):
            continue
        others = [p for r, p in pos.items() if r != (t, n)]
        for ring in range(8):
            nx, ny = legal_spot(x, y, spot, d0 + ring * RING_STEP, others, cfg)
            if not in_area(nx, ny):
                break
        if not on_field(nx, ny):  # behind the goal line or beyond a touch line: off the field of play
            nx, ny = legal_spot(
                x, y, spot, d0, others, cfg, accept=lambda cx, cy: on_field(cx, cy) and not in_area(cx, cy)
            )
        pos[(t, n)] = (nx, ny)
        moves.append((t, n, nx, ny, math.nan))  # nan: keeps its heading
    return moves


class Pitch(Protocol):
    """What `Restarts` needs of the engine's physics (sim/physics/ `Physics`)."""

    tick: int
    attack_dir_a: int

    def stop_play(self) -> None: ...
    def start_play(self) -> None: ...
    def kickoff_positions(self, team: str) -> None: ...
    def pin_ball(self, x: float, y: float) -> None: ...
    def parked(self) -> list[tuple[str, int]]: ...
    def park_robot(self, team: str, n: int) -> object: ...
    def robot_states(self) -> list[tuple]: ...
    def place_robot(self, team: str, n: int, x: float, y: float, theta: float) -> None: ...


class Restarts:
    """Carries the referee's commands out on the field: stoppages, ball spots, legal positions.

    The engine process (processes/engine.py) applies every referee frame with
    it, on its physics (sim/physics/, any `Pitch`). `placed` lists every robot
    moved at a START as (tick, team, n, x, y); `sent_off` every robot parked by
    a RED_CARD, DOUBLE_YELLOW or REPAIR_OUT as (tick, team, n, command).
    """

    def __init__(self, cfg: MatchConfig, physics: Pitch):
        self.cfg = cfg
        self.physics = physics
        self.pending: RefCommand | None = None  # the set piece waiting for its START
        self.placed: list[tuple[int, str, int, float, float]] = []
        self.sent_off: list[tuple[int, str, int, str]] = []  # (tick, team, robot, command)

    def apply_frame(self, frame: Referee) -> None:
        self.physics.attack_dir_a = frame.attack_dir_a
        for c in frame.commands:
            self.apply_command(c)

    def apply_command(self, c: RefCommand) -> None:
        ph = self.physics
        if c.name in SET_PIECES:
            ph.stop_play()
            if c.name == "KICKOFF":
                ph.kickoff_positions(c.team)
            ph.pin_ball(c.x, c.y)
            if c.name == "PENALTY":
                self.place_for_penalty(c)
            self.pending = c
        elif c.name == "START":
            if self.pending is not None:
                self.enforce_distance(self.pending)
                if self.pending.name == "PENALTY":
                    self.place_for_penalty(self.pending)
            self.pending = None
            ph.start_play()
        elif c.name in ("STOP", "HALF_TIME", "END_GAME", "PARK", "GAMEOVER"):
            ph.stop_play()
        elif c.name in SEND_OFF and c.team in TEAMS and 0 <= c.robot < self.cfg.robots:
            if (c.team, c.robot) not in ph.parked():
                ph.park_robot(c.team, c.robot)  # sent off: beyond the fence, no collisions; its process plays on
                self.sent_off.append((ph.tick, c.team, c.robot, c.name))

    def place_for_penalty(self, c: RefCommand) -> None:
        """The penalty procedure: keeper on its line, taker behind the mark, the rest out of the area."""
        ph = self.physics
        parked = set(ph.parked())
        poses = {(t, n): (x, y, th) for t, n, x, y, th, *_ in ph.robot_states() if (t, n) not in parked}
        robots = [(t, n, x, y) for (t, n), (x, y, _) in poses.items()]
        for t, n, x, y, th in penalty_positions(robots, c.team, (c.x, c.y), ph.attack_dir_a, self.cfg):
            ph.place_robot(t, n, x, y, poses[(t, n)][2] if math.isnan(th) else th)
            self.placed.append((ph.tick, t, n, x, y))

    def enforce_distance(self, c: RefCommand) -> None:
        """Move every robot too close to the ball spot of `c` to the nearest legal place."""
        ph = self.physics
        poses = {(t, n): (x, y, th) for t, n, x, y, th, *_ in ph.robot_states()}
        spot = (c.x, c.y)
        rule = keep_away(c.name, c.team, self.cfg)
        robots = [(t, n, x, y) for (t, n), (x, y, _) in poses.items()]
        for t, n in too_close(robots, c.name, c.team, spot, ph.attack_dir_a, self.cfg):
            x, y, th = poses[(t, n)]
            others = [(ox, oy) for r, (ox, oy, _) in poses.items() if r != (t, n)]
            nx, ny = legal_spot(x, y, spot, rule.distance, others, self.cfg)
            ph.place_robot(t, n, nx, ny, th)
            poses[(t, n)] = (nx, ny, th)
            self.placed.append((ph.tick, t, n, nx, ny))
