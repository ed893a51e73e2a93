"""Robot skills as pure geometry: where to stand, where to aim, when to kick.

Everything here is a function of positions in the field frame (schemas/messages.py)
and a frozen `SkillParams`; nothing keeps state, reads a clock or draws random
numbers. The robot brain (:mod:`arena.strategies.iris`) turns the targets into
velocity commands with a navigator of :mod:`arena.navigation`.

Paper 2 (IRIS, "Advance attack and defense strategy ...") gives the behaviours:

* basic strategy: pick up the ball, dribble it, kick from a set distance to goal;
* advance attack (Fig. 7a): detect an opponent in the path (`blocker_ahead`),
  turn the back to it and go round it on the side away from the near touch
  line (`sidestep_side`, `circle_past`: the paper's "circular motion"), go
  goal-ward again once past, shoot when within shooting distance and the line
  to the goal is clear (`line_clear`, `best_aim`); the teammate without the
  ball finds an attacking position (`open_point`);
* advance defense (Fig. 7b): stand on the estimated kick line between the
  opponent ball carrier and our goal, 1 m from the carrier, retreat with it down
  to a 3 m radius around our goal centre, then follow the ball
  (`block_point`); take the ball when within 0.5 m; mark the other opponent
  goal-side (`mark_point`, man-to-man marking);
* ball handling for everyone: approach behind the ball (`behind_point`,
  `lined_up`), step aside after losing a tackle (`aside_point`), pass speed
  (`pass_speed`);
* goalkeeper: guard the goal mouth and intercept the predicted ball path
  (`keeper_target`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from arena.navigation.frames import wrap_angle

Vec = tuple[float, float]


@dataclass(frozen=True)
class SkillParams:
    behind_ball: float = 0.38  # [m] approach point behind the ball, centre to ball centre
    capture_lane: float = 0.18  # [m] lateral error tolerated on the final approach to the ball
    block_distance: float = 1.0  # [m] advance defense: from the carrier on the kick line (paper 2)
    retreat_radius: float = 3.0  # [m] advance defense: closest approach to our goal centre (paper 2)
    block_gap: float = 0.55  # [m] advance defense: blocker centre at least this far from the ball it blocks
    take_distance: float = 0.5  # [m] advance defense: take the ball when this close (paper 2)
    path_corridor: float = 0.8  # [m] half width of the corridor in which an opponent blocks the path
    path_lookahead: float = 2.5  # [m] how far ahead an opponent counts as in the path
    mark_distance: float = 0.8  # [m] advance defense: marker from the marked opponent, towards our goal
    sidestep: float = 1.0  # [m] lateral offset of the sidestep around an opponent
    clear_margin: float = 0.36  # [m] a robot closer than this to the kick line blocks it
    keeper_depth: float = 0.35  # [m] goalkeeper line in front of the goal line
    keeper_post_margin: float = 0.2  # [m] goalkeeper stays this far inside the posts
    intercept_min_speed: float = 0.6  # [m/s] ball speed towards the goal at which the keeper intercepts


def dist(a: Vec, b: Vec) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def angle_to(a: Vec, b: Vec) -> float:
    """Direction [rad] from a to b."""
    return math.atan2(b[1] - a[1], b[0] - a[0])


def clamp(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else hi if x > hi else x


def segment_distance(p: Vec, a: Vec, b: Vec) -> tuple[float, float]:
    """(distance [m] from p to segment a-b, position t in [0, 1] of the closest point)."""
    ax, ay = b[0] - a[0], b[1] - a[1]
    n2 = ax * ax + ay * ay
    t = 0.0 if n2 == 0.0 else clamp(((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / n2, 0.0, 1.0)
    return math.hypot(a[0] + t * ax - p[0], a[1] + t * ay - p[1]), t


def segment_room(points: list[Vec], a: Vec, b: Vec) -> float:
    """The least distance [m] from `points` to segment a-b (inf for none): `segment_distance` of each,
    the same arithmetic with the segment's own terms worked out once (`best_aim` asks it 5 times a call)."""
    a0, a1 = a
    ax, ay = b[0] - a0, b[1] - a1
    n2 = ax * ax + ay * ay
    room = math.inf
    for px, py in points:
        if n2 == 0.0:
            t = 0.0
        else:
            t = ((px - a0) * ax + (py - a1) * ay) / n2
            t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t  # clamp(t, 0.0, 1.0)
        d = math.hypot(a0 + t * ax - px, a1 + t * ay - py)
        if d < room:
            room = d
    return room


def behind_point(ball: Vec, target: Vec, offset: float) -> Vec:
    """The point `offset` [m] behind the ball on the line target -> ball (where to stand to push it to target)."""
    a = angle_to(ball, target)
    return ball[0] - offset * math.cos(a), ball[1] - offset * math.sin(a)


def aside_point(ball: Vec, own_goal: Vec, pos: Vec, offset: float) -> Vec:
    """`offset` [m] from the ball, square to the line ball -> own_goal, on pos's side of that line."""
    a = angle_to(ball, own_goal)
    c, s = math.cos(a), math.sin(a)
    side = 1.0 if -(pos[0] - ball[0]) * s + (pos[1] - ball[1]) * c >= 0.0 else -1.0
    return ball[0] - side * offset * s, ball[1] + side * offset * c


def lined_up(pos: Vec, ball: Vec, target: Vec, lane: float) -> bool:
    """True when pos is behind the ball w.r.t. target and within `lane` [m] of the line through them."""
    a = angle_to(ball, target)
    c, s = math.cos(a), math.sin(a)
    along = (pos[0] - ball[0]) * c + (pos[1] - ball[1]) * s
    across = -(pos[0] - ball[0]) * s + (pos[1] - ball[1]) * c
    return along < 0.0 and abs(across) < lane


def line_clear(a: Vec, b: Vec, robots: list[Vec], margin: float) -> bool:
    """No robot centre within `margin` [m] of the segment a-b (its first 0.3 m excepted: that is us)."""
    for r in robots:
        d, t = segment_distance(r, a, b)
        if d < margin and dist(r, a) > 0.3:
            return False
    return True


def best_aim(
    ball: Vec,
    goal_x: float,
    goal_half: float,
    robots: list[Vec],
    margin: float,
    post_margin: float = 0.25,
    heading: float | None = None,
    turn_cost: float = 0.3,
) -> tuple[Vec, bool]:
    """Aim point on the goal line with the most room, and whether its line is clear.

    Candidates are 5 points across the mouth, `post_margin` inside the posts; the one
    whose line from the ball keeps the largest distance to every robot wins. With
    `heading` [rad] (the shooter's), among the clear candidates the one with the
    most room (up to 1.5 m) less `turn_cost` [m/rad] times the turn it needs wins:
    a shot that needs less turning is taken sooner.
    """
    best: Vec = (goal_x, 0.0)
    best_room = -1.0
    best_turn = math.inf
    inner = goal_half - post_margin
    bx, by = ball
    near: list[Vec] = []
    for r in robots:  # a plain loop: for a few robots cheaper than a comprehension's frame
        if math.hypot(r[0] - bx, r[1] - by) > 0.3:  # dist(r, ball) > 0.3
            near.append(r)
    for i in range(5):
        y = -inner + i * (2.0 * inner / 4.0)
        aim = (goal_x, y)
        room = segment_room(near, ball, aim)
        if heading is not None and room >= margin:
            cost = turn_cost * abs(wrap_angle(math.atan2(y - by, goal_x - bx) - heading)) - min(room, 1.5)  # angle_to
            if best_room < margin or cost < best_turn:
                best, best_room, best_turn = aim, room, cost
        elif room > best_room + 1e-9 and (heading is None or best_room < margin):
            best, best_room = aim, room
    return best, best_room >= margin


def open_point(
    ball: Vec, candidates: list[Vec], opponents: list[Vec], goal_x: float, goal_half: float, margin: float
) -> Vec:
    """Advance attack, the teammate without the ball ("finding attacking positions", paper 2):
    the candidate point with the clearest pass line from the ball and shot line
    to the goal, and the most room from the opponents.

    Score: room [m] to the nearest opponent (at most 2), +1 if the pass line
    from the ball is clear by `margin`, +1 if the best shot line is.
    """
    best, best_score = candidates[0], -math.inf
    for c in candidates:
        room = min((dist(o, c) for o in opponents), default=2.0)
        score = min(room, 2.0)
        if line_clear(ball, c, opponents, margin):
            score += 1.0
        if best_aim(c, goal_x, goal_half, opponents, margin)[1]:
            score += 1.0
        if score > best_score + 1e-9:
            best, best_score = c, score
    return best


def blocker_ahead(pos: Vec, heading_to: Vec, opponents: list[Vec], corridor: float, lookahead: float) -> Vec | None:
    """The nearest opponent in the corridor from pos towards heading_to, at most `lookahead` [m] ahead."""
    a = angle_to(pos, heading_to)
    c, s = math.cos(a), math.sin(a)
    found: Vec | None = None
    best = math.inf
    for o in opponents:
        along = (o[0] - pos[0]) * c + (o[1] - pos[1]) * s
        across = -(o[0] - pos[0]) * s + (o[1] - pos[1]) * c
        if 0.0 < along < lookahead and abs(across) < corridor and along < best:
            found, best = o, along
    return found


def sidestep_side(pos: Vec, goal: Vec) -> float:
    """+1 to pass an opponent on its left (seen towards goal), -1 on its right: away from the near touch line.

    Paper 2: "if the robot is on the left side of the field, the robot will move
    to the right and vice versa" (left: y > 0 when attacking +x).
    """
    a = angle_to(pos, goal)
    ny = math.cos(a)  # y of the unit vector to the left of the goal direction
    side = -1.0 if pos[1] > 0.0 else 1.0  # towards y = 0
    return 1.0 if ny * side >= 0.0 else -1.0


def circle_past(
    pos: Vec, opponent: Vec, goal: Vec, radius: float, step: float = 0.9, rot: float = 0.0
) -> tuple[Vec, float, float]:
    """Advance attack (Fig. 7a, "passing the opposing defender in a circular motion").

    Returns (waypoint, heading, rot): the waypoint lies on the circle of `radius` [m]
    round the opponent, `step` [rad] further round it than we are, going round
    on the side of `sidestep_side` (rot: +1 counter-clockwise, -1 clockwise;
    pass the previous rot back to keep going the same way round); followed
    tick after tick, the robot circles
    the opponent until it is past it. The heading [rad] is the circle's tangent
    the robot moves along: the opponent stays square to its side, so the body
    is between the opponent and the ball in the dribbler (the paper's "turn
    its back to the opponent"; side-on, the ball is 0.56 m or more from the
    opponent's centre, out of its dribbler's reach) and, once past, the robot
    already faces the goal.
    """
    b = angle_to(opponent, pos)  # bearing of us seen from the opponent
    g = angle_to(opponent, goal)
    off = wrap_angle(g - b)
    r = radius
    if dist(pos, opponent) > 1.5 * radius:
        # Still short of it: make for its side, facing the goal, and curve round it from there.
        if rot == 0.0:
            rot = -sidestep_side(pos, goal)
        side = g - rot * math.pi / 2.0  # rot -1 (clockwise) passes on the opponent's left
        return (opponent[0] + r * math.cos(side), opponent[1] + r * math.sin(side)), angle_to(pos, goal), rot
    if abs(off) < step:  # nearly round: head for the goal-ward point of the circle
        return (opponent[0] + r * math.cos(g), opponent[1] + r * math.sin(g)), angle_to(pos, goal), rot
    # Behind the opponent, go round on the chosen side (left of it: clockwise);
    # already beside it, keep going the short way round.
    if rot == 0.0:
        rot = math.copysign(1.0, off) if abs(off) < 2.0 else -sidestep_side(pos, goal)
    a = b + rot * step
    return (opponent[0] + r * math.cos(a), opponent[1] + r * math.sin(a)), wrap_angle(b + rot * math.pi / 2.0), rot


def passed(pos: Vec, opponent: Vec, goal: Vec) -> bool:
    """The opponent is no longer ahead of pos on the way to goal."""
    a = angle_to(pos, goal)
    return (opponent[0] - pos[0]) * math.cos(a) + (opponent[1] - pos[1]) * math.sin(a) <= 0.0


def block_point(carrier: Vec, own_goal: Vec, p: SkillParams, ball: Vec | None = None) -> Vec:
    """Advance defense (paper 2, Fig. 7b): on the estimated kick line to our goal centre.

    `block_distance` from the carrier towards our goal, but never closer than
    `retreat_radius` to the goal centre: once the carrier is within
    retreat_radius + block_distance, the defender stays on the retreat circle
    at the carrier's bearing (it follows the ball instead of backing up).

    With `ball` (the ball the carrier holds, in front of it) the kick line is
    the ball's line to our goal centre, where the kick will start, not the
    carrier centre's: a carrier turning to aim holds the ball up to a robot's
    half size off its own line, enough to open a post for it. The point is
    then on that line `block_distance` from the carrier's centre (the ball's
    distance less), at least `block_gap` from the ball.
    """
    if ball is None:
        d = dist(carrier, own_goal)
        a = angle_to(own_goal, carrier)
        r = max(p.retreat_radius, d - p.block_distance)
        return own_goal[0] + r * math.cos(a), own_goal[1] + r * math.sin(a)
    # dist and angle_to written out: the advance defense asks this every tick
    gx, gy = own_goal
    bx, by = ball
    d = math.hypot(bx - gx, by - gy)  # dist(ball, own_goal)
    a = math.atan2(by - gy, bx - gx)  # angle_to(own_goal, ball)
    gap = max(p.block_gap, p.block_distance - math.hypot(carrier[0] - bx, carrier[1] - by))  # dist(carrier, ball)
    r = max(p.retreat_radius, d - gap)
    return gx + r * math.cos(a), gy + r * math.sin(a)


def mark_point(opponent: Vec, own_goal: Vec, distance: float) -> Vec:
    """Man-to-man marking: `distance` [m] from the opponent towards our goal centre (goal-side)."""
    ox, oy = opponent
    a = math.atan2(own_goal[1] - oy, own_goal[0] - ox)  # angle_to(opponent, own_goal)
    return ox + distance * math.cos(a), oy + distance * math.sin(a)


def predict_crossing(ball: Vec, vel: Vec, line_x: float) -> float | None:
    """y [m] at which a ball rolling with vel [m/s] from ball crosses x = line_x, None if it moves away."""
    dx = line_x - ball[0]
    if vel[0] == 0.0 or dx * vel[0] <= 0.0:
        return None
    return ball[1] + vel[1] * dx / vel[0]


def keeper_target(ball: Vec, ball_vel: Vec, own_goal_x: float, goal_half: float, p: SkillParams) -> tuple[Vec, bool]:
    """Goalkeeper stand point and whether it is intercepting a shot.

    The keeper line is `keeper_depth` in front of our goal line. A ball moving
    towards our goal faster than `intercept_min_speed` is intercepted where its
    path crosses that line (clamped a little outside the posts); otherwise the
    keeper stands where the line from the ball to the goal centre crosses the
    keeper line, inside the posts.
    """
    inward = -1.0 if own_goal_x > 0 else 1.0
    line_x = own_goal_x + inward * p.keeper_depth
    toward = -ball_vel[0] * inward
    if toward > p.intercept_min_speed:
        y = predict_crossing(ball, ball_vel, line_x)
        if y is not None and abs(y) < goal_half + 0.5:
            return (line_x, clamp(y, -goal_half - 0.1, goal_half + 0.1)), True
    lim = goal_half - p.keeper_post_margin
    dx = ball[0] - own_goal_x
    if abs(dx) < 1e-6:
        y = clamp(ball[1], -lim, lim)
    else:
        y = ball[1] * p.keeper_depth / abs(dx)
    low = -lim  # `clamp(y, -lim, lim)` inline: the goalkeeper asks every tick
    return (line_x, low if y < low else lim if y > lim else y), False


def pass_speed(distance: float, arrive: float, decel: float, max_speed: float) -> float:
    """Kick speed [m/s] so that a rolling ball (decel [m/s^2]) arrives with `arrive` [m/s] after distance [m]."""
    return min(max_speed, math.sqrt(arrive * arrive + 2.0 * decel * max(0.0, distance)))
