"""Perception and fusion: the base station's P_A, P_B, P_ball (paper 2, eq. 5) and a robot's own view.

Base station (`TeamModel.update`), from the robots' reports R_n_B = {P_An, P_Bn, P_ball}:

* P_A: each robot's own reported pose (the freshest report wins);
* P_ball: the inverse-variance weighted mean of every visible ball detection
  in the reports of this comm period; a detection at range r has the sensor's
  sigma(r) = det_sigma + det_sigma_per_m * r, so near detections dominate. With
  no detection the previous estimate is kept and ages. The ball velocity is the
  difference of consecutive estimates, smoothed (`vel_smoothing`);
* P_B: opponent detections of all reports, greedily clustered (a detection
  within `merge_radius` of a cluster joins it, weighted as above), at most
  `robots` clusters; an opponent seen before and not re-detected keeps its
  last position while younger than `opponent_memory`.

Robot (`RobotView.update`): its own pose is the sensed one; the ball is its own
detection when visible, otherwise the base station's P_ball of the latest order
(aged by the order's delay) or its own last detection, whichever is younger;
opponents are its own detections plus the order's P_B entries that no own
detection explains. Robots never see ground truth.

Latency (`RobotView.opponents_now`, `pose_now`): a robot sees the world
`latency` ticks late (`timing.perception_latency`). It tracks each opponent it
detects (a detection within `merge_radius` of a track's last one continues it)
and estimates the opponent's velocity by linear regression over the track's
last `track_window` detections (CAMBADA's world model, Silva et al., "World
modeling on an MSL robotic soccer team", Mechatronics 21, 2011: linear
regression for the velocities of the ball and the robots), then predicts
where the opponent is now, `latency` ticks on; its own pose it moves on by its
odometry velocity (Brainstormers Tribots: the sensor latency is bridged by
predicting the tracked objects and the robot itself forward with their
estimated motion).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from math import cos, hypot, sin
from operator import itemgetter

from arena.config import SensorParams
from arena.schemas.messages import Order, Report, Sense
from arena.schemas.vocabulary import other_team

Vec = tuple[float, float]
# a track: where it was last seen (x, y), then its detections as columns: their ticks, x and y; last, where it is
# predicted now, once worked out this tick (None before)
Tracked = list


@dataclass(frozen=True)
class FusionParams:
    merge_radius: float = 0.5  # [m] detections closer than this are the same robot
    opponent_memory: int = 100  # [ticks] an unseen opponent is forgotten after this long
    ball_memory: int = 250  # [ticks] a ball estimate older than this is not used
    vel_smoothing: float = 0.5  # [-] weight of the newest velocity sample (exponential filter)
    track_window: int = 10  # [detections] an opponent's velocity: linear regression over its last this many
    max_ball_speed: float = 10.0  # [m/s] faster jumps between estimates are noise, not motion


_WEIGHT = itemgetter(2)  # a cluster's total weight


def detection_sigma(sensor: SensorParams, rng_m: float) -> float:
    """Sensor noise [m] of a detection at range rng_m [m]."""
    return sensor.det_sigma + sensor.det_sigma_per_m * rng_m


@dataclass(slots=True)
class Track:
    x: float
    y: float
    tick: int

    @property
    def xy(self) -> Vec:
        return self.x, self.y


class BallFilter:
    """Position and smoothed velocity from a sequence of stamped estimates."""

    def __init__(self, p: FusionParams, dt: float):
        self.p = p
        self.dt = dt
        self.track: Track | None = None
        self.vel: Vec = (0.0, 0.0)
        self._max_speed = p.max_ball_speed  # [m/s]
        self._w, self._keep = p.vel_smoothing, 1 - p.vel_smoothing  # weights of the newest sample and the rest

    def observe(self, tick: int, x: float, y: float) -> None:
        t = self.track
        if t is None:
            self.track = Track(x, y, tick)
            return
        gap = tick - t.tick  # [ticks]
        if gap > 0:  # `tick > t.tick`: integers
            span = gap * self.dt
            vx, vy = (x - t.x) / span, (y - t.y) / span
            if hypot(vx, vy) <= self._max_speed and gap <= 10:
                w, keep, vel = self._w, self._keep, self.vel
                self.vel = (w * vx + keep * vel[0], w * vy + keep * vel[1])
            else:
                self.vel = (0.0, 0.0)
        t.x, t.y, t.tick = x, y, tick  # the track is read, never kept, by this module's callers

    def age(self, tick: int) -> int:
        return tick - self.track.tick if self.track is not None else 1 << 30


def cluster(detections: list[tuple[float, float, float]], radius: float) -> list[tuple[float, float, float]]:
    """Greedy weighted clustering of (x, y, weight) in order; returns (x, y, total weight) per cluster."""
    out: list[list[float]] = []  # sum wx, sum wy, sum w
    for x, y, w in detections:
        for c in out:
            if math.hypot(c[0] / c[2] - x, c[1] / c[2] - y) < radius:
                c[0] += w * x
                c[1] += w * y
                c[2] += w
                break
        else:
            out.append([w * x, w * y, w])
    clusters: list[tuple[float, float, float]] = []
    for c in out:  # a plain loop: for a few clusters cheaper than a comprehension's frame
        clusters.append((c[0] / c[2], c[1] / c[2], c[2]))
    return clusters


class TeamModel:
    """The base station's fused world model (eq. 5)."""

    def __init__(self, team: str, robots: int, sensor: SensorParams, dt: float, p: FusionParams = FusionParams()):
        self.team = team
        self.other = other_team(team)
        self.robots = robots
        self.sensor = sensor
        self.p = p
        self.own: dict[int, tuple[float, float, float, int]] = {}  # n -> x, y, theta, tick
        self.has_ball: dict[int, bool] = {}
        self.ball = BallFilter(p, dt)
        self.opponents: list[Track] = []

    def update(self, tick: int, reports: dict[int, Report]) -> None:
        balls: list[tuple[float, float, float]] = []
        seen: list[tuple[float, float, float]] = []
        newest = -1
        own, has_ball, other, hypot = self.own, self.has_ball, self.other, math.hypot
        det, per_m = self.sensor.det_sigma, self.sensor.det_sigma_per_m  # `detection_sigma`, inlined
        for n in sorted(reports):
            rep = reports[n]
            pose = rep.pose
            px, py = pose.x, pose.y
            if n not in own or rep.tick >= own[n][3]:
                own[n] = (px, py, pose.theta, rep.tick)
                has_ball[n] = rep.has_ball
            b = rep.ball
            if b.visible:
                s = det + per_m * hypot(b.x - px, b.y - py)
                balls.append((b.x, b.y, 1.0 / (s * s)))
                if rep.tick > newest:
                    newest = rep.tick
            for r in rep.robots:
                if r.team == other:
                    s = det + per_m * hypot(r.x - px, r.y - py)
                    seen.append((r.x, r.y, 1.0 / (s * s)))
        if balls:  # `cluster(balls, math.inf)[0]`, inlined: the first detection and every later one that joins it
            x, y, sw = balls[0]
            sx, sy = sw * x, sw * y
            for x, y, w in balls[1:]:
                if hypot(sx / sw - x, sy / sw - y) < math.inf:
                    sx += w * x
                    sy += w * y
                    sw += w
            self.ball.observe(newest, sx / sw, sy / sw)
        robots, merge = self.robots, self.p.merge_radius
        # heaviest first, ties in cluster order: reverse keeps a sort stable, so the order of key=-weight, without
        # a Python call per cluster (weights are finite: 1 / s^2 of finite detections)
        fresh = sorted(cluster(seen, merge), key=_WEIGHT, reverse=True)[:robots]
        tracks: list[Track] = []
        for x, y, _ in fresh:  # a plain loop: for three or so, cheaper than a comprehension
            tracks.append(Track(x, y, tick))
        oldest = tick - self.p.opponent_memory
        for old in self.opponents:
            if len(tracks) >= robots or old.tick < oldest:
                continue
            ox, oy = old.x, old.y
            for t in tracks:
                if not hypot(ox - t.x, oy - t.y) >= merge:  # not `<`: a NaN counts as near, as it did
                    break
            else:
                tracks.append(old)
        self.opponents = tracks

    def holder(self) -> int | None:
        has_ball = self.has_ball
        for n in sorted(has_ball):  # the lowest-numbered robot holding the ball; a plain loop, no list
            if has_ball[n]:
                return n
        return None

    def ball_xy(self, tick: int) -> Vec | None:
        t = self.ball.track
        if t is None or tick - t.tick > self.p.ball_memory:
            return None
        return t.xy


def _consecutive(n: int) -> tuple[tuple[float, ...], float]:
    """For n consecutive ticks t0 .. t0 + n - 1: each t - mean(t), and the sum of their squares, in the
    order `_regression_velocity` adds them. The mean is t0 + (n - 1) / 2, a multiple of 1/2 and exact,
    so each t - mean is i - (n - 1) / 2 whatever t0 is: the same floats as the general loop gives."""
    mt = sum(range(n)) / n
    ds = tuple(t - mt for t in range(n))
    stt = 0.0
    for d in ds:
        stt += d * d
    return ds, stt


_CONSECUTIVE = {n: _consecutive(n) for n in range(3, 65)}


@cache  # one function per window length, period and latency, per process
def _unrolled_ahead(n: int, stt_dt: float, lead: float) -> Callable[[list[float], list[float]], Vec]:
    """For a consecutive track of n detections, a function of its xs and ys giving where `_regression_velocity`'s
    velocity moves its last detection in lead [s]: (x_last + sum(d * (x - mean x)) / stt_dt * lead, the same in y),
    with stt_dt = stt * dt. The loop written out, term by term from 0.0 in the same order with the same offsets d,
    so the same floats, without the loop's per-item interpreter work."""
    ds, _ = _CONSECUTIVE[n]
    xs, ys = (", ".join(f"{c}{i}" for i in range(n)) for c in "xy")
    sx, sy = (" + ".join(f"{d!r} * ({c}{i} - m{c})" for i, d in enumerate(ds)) for c in "xy")
    src = (
        f"def ahead(xs, ys):\n    {xs}, = xs\n    {ys}, = ys\n    mx = sum(xs) / {n}\n    my = sum(ys) / {n}\n"
        f"    return x{n - 1} + (0.0 + {sx}) / {stt_dt!r} * {lead!r}, y{n - 1} + (0.0 + {sy}) / {stt_dt!r} * {lead!r}\n"
    )
    scope: dict = {}
    exec(compile(src, f"<_unrolled_ahead({n})>", "exec"), scope)  # our own text, from numbers only
    return scope["ahead"]


def _regression_velocity(ts: list[int], xs: list[float], ys: list[float], dt: float) -> Vec:
    """[m/s] The least-squares slope of x and y over the ticks ts (rising); (0, 0) with fewer than 3 points."""
    n = len(ts)
    if n < 3:
        return 0.0, 0.0
    mx = sum(xs) / n
    my = sum(ys) / n
    if ts[-1] - ts[0] == n - 1 and n in _CONSECUTIVE:  # a detection every tick (ticks rise: `_track`)
        ds, stt = _CONSECUTIVE[n]
        sxt = syt = 0.0
        for d, x, y in zip(ds, xs, ys):
            sxt += d * (x - mx)
            syt += d * (y - my)
        return sxt / (stt * dt), syt / (stt * dt)
    mt = sum(ts) / n
    stt = sxt = syt = 0.0
    for t, x, y in zip(ts, xs, ys):
        d = t - mt
        stt += d * d
        sxt += d * (x - mx)
        syt += d * (y - my)
    if stt <= 0.0:
        return 0.0, 0.0
    return sxt / (stt * dt), syt / (stt * dt)


class RobotView:
    """One robot's picture of the world for this tick."""

    # slots: an instance dict of 30 keys or more loses CPython 3.11's shared keys, and every method call
    # on the instance then costs ~250 instructions more
    __slots__ = (
        "team other n p lead _tracks _now _predict _unexplained sensor dt own_ball pose vel "
        "pose_now omega ball ball_vel ball_age opponents mates has_ball _near _mate_obstacles _order "
        "_order_opponent_xy _order_opponents_until _mate_xy _merge2 _merge_far _tracking _opponent_memory "
        "_ball_memory __dict__"
    ).split()

    def __init__(
        self, team: str, n: int, sensor: SensorParams, dt: float, p: FusionParams = FusionParams(), latency: int = 0
    ):
        self.team = team
        self.other = other_team(team)
        self.n = n
        self.p = p
        self.lead = latency * dt  # [s] how far the view is behind the present
        self._tracks: list[Tracked] = []  # per opponent seen: its last detections
        self._now: list[Vec] | None = []  # see `opponents_now`
        self._window = window = p.track_window
        # Per consecutive track length n (a list, indexed by n up to the longest track, for the cheapest lookup):
        # `_regression_velocity`'s tick offsets and stt * dt, and a bound: |prediction - last detection| <= reach *
        # the spread of the detections (|sum d (x - mean)| <= sum |d| * spread); None for n < 3 (no regression)
        slopes: list[tuple[tuple[float, ...], float, float] | None] = [None] * (max(window, 1) + 1)
        for k, (ds, stt) in _CONSECUTIVE.items():
            if k < len(slopes):
                slopes[k] = (ds, stt * dt, sum(map(abs, ds)) / (stt * dt) * self.lead * (1 + 1e-9))
        full = slopes[window] if window > 0 else None  # a full window's: its prediction written out
        ahead = (window, _unrolled_ahead(window, full[1], self.lead)) if full is not None else (-1, None)
        self._predict = (slopes, self.lead, *ahead)  # what `opponents_near` reads, in one attribute
        self._unexplained: list[Vec] = []  # the order's opponents that no own detection of this tick explains
        self.sensor = sensor
        self.dt = dt
        self.own_ball = BallFilter(p, dt)
        self.pose: tuple[float, float, float] | None = None
        self.vel: Vec = (0.0, 0.0)  # [m/s] the robot's velocity in the field frame (odometry, sensed in the body frame)
        # [m] Where the robot is now: its sensed position moved on by `latency` ticks at its odometry velocity
        self.pose_now: Vec | None = None
        self.omega = 0.0  # [rad/s] odometry
        self.ball: Vec | None = None
        self.ball_vel: Vec = (0.0, 0.0)
        self.ball_age = 1 << 30  # [ticks]
        self.opponents: list[Vec] = []
        self.mates: dict[int, tuple[float, float, str]] = {}  # n -> x, y, role
        self.has_ball = False
        self._near: list[Vec] = []  # teammates seen this tick
        self._mate_obstacles: list[Vec] | None = []  # see `mate_obstacles`
        self._order: Order | None = None
        self._order_opponent_xy: list[Vec] = []  # the positions of the order's P_B entries ...
        self._order_opponents_until = 0  # [tick] ... and the last tick at which none of them is too old
        self._mate_xy: list[Vec] = []  # the teammates' positions of the order
        self._merge2 = p.merge_radius * p.merge_radius  # [m^2]
        # [m] two points this far apart along one axis are not within merge_radius: d ** 2 >= _merge2 (pow errs
        # by under an ulp, a sum of squares rounds up from either), so `_track` skips such a pair's distance
        self._merge_far = far = abs(p.merge_radius) * (1 + 1e-9)
        self._tracking = (self._merge2, window, far, -far)  # what `_track` reads, in one attribute
        self._opponent_memory = p.opponent_memory
        self._ball_memory = p.ball_memory

    def update(self, tick: int, sense: Sense | None, order: Order | None) -> None:
        seen: list[Vec] = []  # own detections: opponents ...
        near: list[Vec] = []  # ... and teammates
        own_ball = self.own_ball
        if sense is not None:
            other = self.other
            for r in sense.robots:
                (seen if r.team == other else near).append((r.x, r.y))
            p = sense.pose
            x, y, theta = self.pose = (p.x, p.y, p.theta)
            c, s = cos(theta), sin(theta)
            svx, svy = sense.vx, sense.vy
            vx, vy = self.vel = (c * svx - s * svy, s * svx + c * svy)
            lead = self.lead
            self.pose_now = (x + vx * lead, y + vy * lead) if lead != 0.0 else (x, y)
            self.omega = sense.omega
            self.has_ball = sense.has_ball
            b = sense.ball
            if b.visible:
                own_ball.observe(tick, b.x, b.y)
            if lead > 0.0:
                if seen or self._tracks:  # nothing seen now or before (a quarter of the ticks): no tracks, as they were
                    self._track(sense.tick, seen)
                self._now = None  # predicted when asked for (`opponents_now`, `opponents_near`)
        elif order is not None and self.pose is None:
            self._pose_from_order(order)
        # The ball: the own detection or the order's, whichever is younger (the own one on a tie).
        track = own_ball.track
        order_age = order.ball_age + (tick - order.tick) if order is not None and order.ball_valid else None
        if track is not None and (order_age is None or tick - track.tick <= order_age):
            ball, self.ball_vel, age = (track.x, track.y), own_ball.vel, tick - track.tick
        elif order_age is not None:
            ball, self.ball_vel, age = (order.ball_x, order.ball_y), (0.0, 0.0), order_age  # type: ignore[union-attr]
        else:
            ball, self.ball_vel, age = None, (0.0, 0.0), 1 << 30
        self.ball_age = age
        self.ball = None if age > self._ball_memory else ball
        if order is not self._order:  # the teammates and the base station's opponents change with the order only
            self._take_order(order)
        # The base station's entries that no own detection within merge_radius explains.
        unexplained: list[Vec] = []
        if order is not None:
            # none too old (the usual case): all of them; else those young enough (rare)
            entries = (
                self._order_opponent_xy
                if tick <= self._order_opponents_until
                else self._younger(self._opponent_memory - (tick - order.tick))
            )
            merge2 = self._merge2
            for xy in entries:  # the view's hottest loop
                ex, ey = xy
                for ox, oy in seen:
                    dx, dy = ex - ox, ey - oy
                    if dx * dx + dy * dy < merge2:
                        break
                else:
                    unexplained.append(xy)
        seen += unexplained  # `seen` is this tick's own, kept nowhere else: extended in place, no new list
        self.opponents = seen
        self._unexplained = unexplained  # `opponents_near` adds them to its predictions
        self._near = near
        self._mate_obstacles = None  # worked out when asked for (`mate_obstacles`)

    def _pose_from_order(self, order: Order) -> None:
        """Before the first sense: the robot's own pose as the order lists it."""
        for tp in order.own:
            if tp.robot == self.n:
                self.pose = (tp.x, tp.y, tp.theta)
                vx, vy = self.vel
                lead = self.lead
                self.pose_now = (tp.x + vx * lead, tp.y + vy * lead) if lead != 0.0 else (tp.x, tp.y)

    def _younger(self, memory: int) -> list[Vec]:
        """The positions of the order's opponents no older than memory [ticks]."""
        return [xy for tp, xy in zip(self._order.opponents, self._order_opponent_xy) if tp.age <= memory]  # type: ignore[union-attr]

    def _take_order(self, order: Order | None) -> None:
        """What follows from a new order alone: the teammates and the base station's opponents."""
        # plain loops, one pass per list: for three or so entries cheaper than comprehensions and max()
        self._order = order
        mates: dict[int, tuple[float, float, str]] = {}
        mate_xy: list[Vec] = []
        xys: list[Vec] = []
        oldest = 0
        if order is not None:
            n = self.n
            for tp in order.own:
                if tp.robot != n:
                    mates[tp.robot] = (tp.x, tp.y, tp.role)
            for x, y, _ in mates.values():  # a robot listed twice: its last entry, as the dict holds
                mate_xy.append((x, y))
            for tp in order.opponents:
                xys.append((tp.x, tp.y))
                if tp.age > oldest:  # never below 0: the filter in `update` then runs, with the same result
                    oldest = tp.age
        self.mates, self._mate_xy = mates, mate_xy
        self._order_opponent_xy = xys
        # oldest + (tick - order.tick) <= opponent_memory, solved for tick (integers: exact)
        self._order_opponents_until = order.tick + self._opponent_memory - oldest if order is not None else 0

    def _track(self, tick: int, seen: list[Vec]) -> None:
        """Continue each track with the detection nearest its last one (within merge_radius), start new ones."""
        old = self._tracks
        merge2, window, far, nfar = self._tracking
        tracks: list[Tracked] = []
        for x, y in seen:
            best, best_d2 = None, merge2
            for t in old:
                dx = t[0] - x
                if dx < far and dx > nfar:  # farther apart along x: surely not within merge_radius (`_merge_far`)
                    d2 = dx**2 + (t[1] - y) ** 2
                    if d2 < best_d2:
                        best, best_d2 = t, d2
            if best is None:
                tracks.append([x, y, [tick], [x], [y], None])
                continue
            old.remove(best)
            _, _, ts, xs, ys, _ = best
            n = len(ts)
            if ts[n - 1] >= tick:  # the same sense again: the newer detection replaces it (n - 1: not the slow -1)
                ts.pop()
                xs.pop()
                ys.pop()
            elif n >= window:  # a full window: its oldest detection goes (before the append: no regrowth)
                del ts[0], xs[0], ys[0]
            ts.append(tick)
            xs.append(x)
            ys.append(y)
            best[0] = x  # the track itself moved on, not a new list: its last point, no prediction yet
            best[1] = y
            best[5] = None
            tracks.append(best)
        self._tracks = tracks

    @property
    def opponents_now(self) -> list[Vec]:
        """The opponents where they are now: own detections moved on by `latency` ticks at their
        regressed velocity, then the base station's entries as in `opponents` (no velocity)."""
        if self.lead == 0.0:
            return self.opponents
        now = self._now
        if now is None:
            now = self._now = self.opponents_near(0.0, 0.0, math.inf)
        return now

    def opponents_near(self, x: float, y: float, rng: float) -> list[Vec]:
        """`opponents_now` less tracked opponents that are surely farther than rng [m] from (x, y) along x or y.

        The same positions in the same order, only fewer: a caller that skips what lies outside that box
        gets the same result from either. A track is predicted only when it may be inside: the regression
        is most of the view's work (the bound: `_predict`'s slopes, plus 1 um for rounding).
        """
        if self.lead == 0.0:
            return self.opponents
        if self._now is not None:
            return self._now
        slopes, lead, window, window_ahead = self._predict
        out: list[Vec] = []
        rng += 1e-6  # [m] beyond every rounding of a prediction (positions on a field: |x|, |y| << 1e6 m)
        for t in self._tracks:
            p = t[5]  # the prediction kept in the track: no enumerate, no list of them per tick
            if p is None:
                lx, ly, ts, xs, ys, _ = t
                n = len(ts)
                m = n - 1  # the last detection's index: a negative index takes the interpreter's slow path
                c = slopes[n] if ts[m] - ts[0] == m else None
                if c is None:  # fewer than 3 detections, or a gap: the general regression
                    vx, vy = _regression_velocity(ts, xs, ys, self.dt)
                    p = t[5] = (lx + vx * lead, ly + vy * lead)
                    out.append(p)
                    continue
                # `_regression_velocity` of a consecutive track, inlined: the usual case
                ds, stt_dt, reach = c
                d = lx - x
                out_x = (d if d >= 0.0 else -d) - rng  # [m] how far outside the box (abs, inline); the spread only then
                if out_x > 0.0:
                    s = sorted(xs)  # the spread: one sort of ten floats costs half of max() and min()
                    if out_x > reach * (s[m] - s[0]):
                        continue
                d = ly - y
                out_y = (d if d >= 0.0 else -d) - rng
                if out_y > 0.0:
                    s = sorted(ys)
                    if out_y > reach * (s[m] - s[0]):
                        continue
                if n == window:  # a full window: the usual case
                    p = t[5] = window_ahead(xs, ys)
                else:
                    mx = sum(xs) / n
                    my = sum(ys) / n
                    sxt = syt = 0.0
                    for d, u, v in zip(ds, xs, ys):
                        sxt += d * (u - mx)
                        syt += d * (v - my)
                    p = t[5] = (lx + sxt / stt_dt * lead, ly + syt / stt_dt * lead)
            out.append(p)
        out += self._unexplained
        return out

    @property
    def mate_obstacles(self) -> list[Vec]:
        """The teammates' positions: own detections first, then the order's that no own detection explains."""
        mates = self._mate_obstacles
        if mates is None:
            near, merge2 = self._near, self._merge2
            mates = near[:]
            for xy in self._mate_xy:  # each with no own detection within merge_radius
                x, y = xy
                for a, b in near:
                    dx, dy = x - a, y - b
                    if dx * dx + dy * dy < merge2:
                        break
                else:
                    mates.append(xy)
            self._mate_obstacles = mates
        return mates

    def others(self) -> list[Vec]:
        """Every other robot's position (obstacles): own detections first, then the base station's."""
        return self.opponents + self.mate_obstacles
