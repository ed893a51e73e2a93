"""Fuzzy social force model (F-SFM) of paper 1 (Dewantara, Ariyadi and Oktavianto,
"Responsive Motion Control for Robot Soccer Navigation Using Adaptive Social
Force Framework", 2021), eq. 8-14 and the rule table of its Fig. 4.

A fuzzy inference system (FIS) maps each obstacle's distance d and relative
direction gamma to the gain k of that obstacle's force in the SFM (eq. 6-7,
:mod:`arena.navigation.sfm`); everything else is the SFM. Per obstacle j:

Eq. 12, distance:           d = ||O - R||  (centre to centre) [m]
Eq. 13-14, bearings:        beta = atan2(G - R),  gamma = atan2(O - R) [rad]
Relative direction:         phi = |wrap(gamma - beta)| in [0, pi] [rad], the obstacle's
                            angle off the robot's front; the front is the goal direction
                            beta (the heading PID of eq. 15-16 turns the robot to face
                            beta), or the velocity direction with ``front="velocity"``.
Eq. 8, triangular MF:       mu(x) = (x-u)/(v-u) if u < x <= v;  (w-x)/(w-v) if v < x <= w;  0 otherwise
                            (u = v: left shoulder, mu = 1 for x <= v; v = w: right shoulder)
Eq. 9, firing strengths:    B_ab = mu^d_a(d) * mu^gamma_b(phi)   (product T-norm)
Fig. 4, rules:              R_ab, the risk label for direction b and distance a
Eq. 10, centre of area:     k = sum_ab B_ab R_ab / sum_ab B_ab

The paper's Fig. 3 (the membership functions) is not in the text. The
distance sets follow Hall's proxemics (intimate < 0.45 m, personal 0.45-1.2 m,
social 1.2-3.6 m, public > 3.6 m): triangles centred at 0, 0.9, 1.5 and 5.7 m,
so that neighbouring sets cross at 0.5 exactly on Hall's boundaries and the set
with the largest degree is always Hall's zone. The direction sets are centred at
0, 60, 120 and 180 degrees (front, side-front, side-back, back), crossing at
30, 90 and 150 degrees. Both partitions sum to 1 everywhere, so sum B = 1 and k
is a bilinear interpolation of the rule table between set centres.

Output sets (Table 3): scheme #5 VH, H, M, L, VL = 200, 150, 100, 50, 25.
Scheme #6's row is garbled in the text (only VH = 600 and VL = 75 survive);
both are 3x scheme #5, as the fixed-k schemes #2/#1 are (300/100), so #6 is
taken as 600, 450, 300, 150, 75.

The FIS runs on Python floats: for two inputs and 4 + 4 sets this is faster
than numpy, whose per-call overhead dominates arrays this small
(docs/performance.md, "Measurements behind design choices").
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

from arena.navigation.base import EPS_DISTANCE, Vec2, points, xy
from arena.navigation.frames import wrap_angle
from arena.navigation.sfm import SFMParams, command_velocity, goal_force

_PI = math.pi
_TAU = 2.0 * _PI
atan2, exp, hypot, remainder = math.atan2, math.exp, math.hypot, math.remainder


@dataclass(frozen=True)
class TriangularMF:
    """Eq. 8 with left boundary u, centre v, right boundary w (same unit as the input)."""

    u: float
    v: float
    w: float

    def __post_init__(self) -> None:
        if not self.u <= self.v <= self.w or self.u == self.w:
            raise ValueError(f"need u <= v <= w and u < w, got {self}")

    def degree(self, x: float) -> float:
        """mu(x) in [0, 1] by eq. 8; a set with u == v (v == w) is a left (right) shoulder."""
        u, v, w = self.u, self.v, self.w
        if x <= v:
            if u == v:
                return 1.0
            return (x - u) / (v - u) if x > u else 0.0
        if v == w:
            return 1.0
        return (w - x) / (w - v) if x < w else 0.0


# Hall's proxemic zone boundaries, centre-to-centre distance [m].
HALL_INTIMATE = 0.45  # [m] intimate | personal
HALL_PERSONAL = 1.2  # [m] personal | social
HALL_SOCIAL = 3.6  # [m] social | public

# Set centres [m] chosen so that neighbours cross at 0.5 on Hall's boundaries.
_C_INTIMATE = 0.0  # [m]
_C_PERSONAL = 2.0 * HALL_INTIMATE - _C_INTIMATE  # 0.9 [m]
_C_SOCIAL = 2.0 * HALL_PERSONAL - _C_PERSONAL  # 1.5 [m]
_C_PUBLIC = 2.0 * HALL_SOCIAL - _C_SOCIAL  # 5.7 [m]

DISTANCE_SETS: tuple[TriangularMF, ...] = (
    TriangularMF(_C_INTIMATE, _C_INTIMATE, _C_PERSONAL),  # intimate (left shoulder)
    TriangularMF(_C_INTIMATE, _C_PERSONAL, _C_SOCIAL),  # personal
    TriangularMF(_C_PERSONAL, _C_SOCIAL, _C_PUBLIC),  # social
    TriangularMF(_C_SOCIAL, _C_PUBLIC, _C_PUBLIC),  # public (right shoulder)
)
DISTANCE_LABELS = ("intimate", "personal", "social", "public")

# Relative direction |phi| [rad], centres every 60 degrees.
DIRECTION_SETS: tuple[TriangularMF, ...] = (
    TriangularMF(0.0, 0.0, _PI / 3.0),  # front (left shoulder at 0)
    TriangularMF(0.0, _PI / 3.0, 2.0 * _PI / 3.0),  # side-front
    TriangularMF(_PI / 3.0, 2.0 * _PI / 3.0, _PI),  # side-back
    TriangularMF(2.0 * _PI / 3.0, _PI, _PI),  # back (right shoulder at pi)
)
DIRECTION_LABELS = ("front", "side-front", "side-back", "back")

# Fig. 4: rows are directions (front .. back), columns distances (intimate .. public).
RULES: tuple[tuple[str, ...], ...] = (
    ("VH", "H", "H", "H"),
    ("H", "H", "M", "L"),
    ("M", "M", "L", "L"),
    ("L", "L", "L", "VL"),
)


@dataclass(frozen=True)
class OutputSets:
    """Singleton output values of the risk labels, i.e. the k they stand for [N] (and [N/m], eq. 7)."""

    VH: float
    H: float
    M: float
    L: float
    VL: float


SCHEME_5 = OutputSets(VH=200.0, H=150.0, M=100.0, L=50.0, VL=25.0)  # paper 1 Table 3
SCHEME_6 = OutputSets(VH=600.0, H=450.0, M=300.0, L=150.0, VL=75.0)  # Table 3, garbled row read as 3x #5


@dataclass(frozen=True)
class FIS:
    """The fuzzy inference system of eq. 8-10: input sets, rule labels and output values."""

    distance_sets: tuple[TriangularMF, ...] = DISTANCE_SETS
    direction_sets: tuple[TriangularMF, ...] = DIRECTION_SETS
    rules: tuple[tuple[str, ...], ...] = RULES
    outputs: OutputSets = SCHEME_5
    # rules resolved to numbers, [direction][distance]; derived in __post_init__.
    table: tuple[tuple[float, ...], ...] = field(init=False, repr=False, compare=False)
    # the sets as (index, u, v, w, v - u, w - v) for `gain`; derived in __post_init__.
    distance_mf: tuple[tuple[int, float, float, float, float, float], ...] = field(
        init=False, repr=False, compare=False
    )
    direction_mf: tuple[tuple[int, float, float, float, float, float], ...] = field(
        init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if len(self.rules) != len(self.direction_sets) or any(len(r) != len(self.distance_sets) for r in self.rules):
            raise ValueError("rules must have one row per direction set and one column per distance set")
        object.__setattr__(self, "table", tuple(tuple(getattr(self.outputs, lab) for lab in row) for row in self.rules))
        for name, sets in (("distance_mf", self.distance_sets), ("direction_mf", self.direction_sets)):
            object.__setattr__(self, name, tuple((i, s.u, s.v, s.w, s.v - s.u, s.w - s.v) for i, s in enumerate(sets)))
        # not a field: both inputs' `_spans` for `step`, None unless both are Ruspini partitions (the paper's are)
        spans = _spans(self.distance_mf), _spans(self.direction_mf)
        object.__setattr__(self, "partition", None if None in spans else spans)


def _spans(mf: tuple[tuple[int, float, float, float, float, float], ...]) -> tuple | None:
    """Sets that form a Ruspini partition (a left shoulder, triangles, a right shoulder, each reaching to its
    neighbours' centres, the centres increasing) as (first centre, last centre, spans); spans[k] =
    (w_k, w_k - v_k, u_k+1, v_k+1 - u_k+1) between the centres of sets k and k + 1, where only those two sets
    have a degree: (w_k - x) / (w_k - v_k) and (x - u_k+1) / (v_k+1 - u_k+1) by eq. 8. None for other sets."""
    if len(mf) < 2 or mf[0][1] != mf[0][2] or mf[-1][2] != mf[-1][3]:
        return None
    spans = []
    for (_, _, v, w, _, wv), (_, u2, v2, _, vu2, _) in zip(mf, mf[1:]):
        if not (v < v2 and w == v2 and u2 == v):
            return None
        spans.append((w, wv, u2, vu2))
    return mf[0][2], mf[-1][2], tuple(spans)


@dataclass(frozen=True)
class FSFMParams:
    sfm: SFMParams = SFMParams()  # eq. 3-7, 17-20 parameters; sfm.k is unused (the FIS sets k)
    fis: FIS = FIS()  # eq. 8-10
    front: Literal["goal", "velocity"] = "goal"  # what "front" means for the direction input
    min_speed_for_front: float = 0.05  # [m/s] below this, front="velocity" falls back to the goal direction

    def __post_init__(self) -> None:
        # not a field: what `step` reads every call, None for a FIS that is not a Ruspini partition
        sfm = self.sfm
        flat = None
        if self.fis.partition is not None:
            flat = (
                *(sfm.mass / sfm.tau, sfm.max_speed, sfm.r_ij, sfm.sigma, sfm.cutoff_distance),
                *(sfm.tau / sfm.mass, sfm.integrate, self.front == "velocity", self.min_speed_for_front),
                *(*self.fis.partition, self.fis.table),
            )
        object.__setattr__(self, "flat", flat)

    @property
    def max_speed(self) -> float:
        """v0 [m/s], so that every navigator's params expose ``max_speed``."""
        return self.sfm.max_speed


DEFAULT = FSFMParams()
SCHEME_5_PARAMS = FSFMParams(fis=FIS(outputs=SCHEME_5))
SCHEME_6_PARAMS = FSFMParams(fis=FIS(outputs=SCHEME_6))


def memberships(x: float, sets: Sequence[TriangularMF]) -> list[float]:
    """Eq. 8 for every set: the degrees of ``x``."""
    return [s.degree(x) for s in sets]


def firing_strengths(d: float, phi: float, fis: FIS = FIS()) -> list[list[float]]:
    """Eq. 9: B[b][a] = mu^gamma_b(phi) * mu^d_a(d), rows direction b, columns distance a."""
    mu_d = memberships(d, fis.distance_sets)
    return [[mg * md for md in mu_d] for mg in memberships(abs(phi), fis.direction_sets)]


def _degrees(x: float, sets: tuple[tuple[int, float, float, float, float, float], ...]) -> list[tuple[int, float]]:
    """(index, mu(x)) of every set with a non-zero degree: eq. 8, `TriangularMF.degree` with the
    same arithmetic on the sets' precomputed (index, u, v, w, v - u, w - v) (this runs per obstacle and tick)."""
    out = []
    for i, u, v, w, vu, wv in sets:
        if x <= v:
            m = 1.0 if u == v else (x - u) / vu if x > u else 0.0
        else:
            m = 1.0 if v == w else (w - x) / wv if x < w else 0.0
        if m > 0.0:
            out.append((i, m))
    return out


def gain(d: float, phi: float, fis: FIS = FIS()) -> float:
    """Eq. 8-10: the obstacle gain k for distance ``d`` [m] and relative direction ``phi`` [rad].

    ``phi`` may be signed; left and right are symmetric. Only the sets with
    a non-zero degree take part (at most two per input with these partitions).
    The direction degrees are `_degrees` inlined (this runs per obstacle and tick), the same arithmetic.
    """
    mu_d = _degrees(d, fis.distance_mf)
    num = den = 0.0
    table = fis.table
    x = abs(phi)
    for b, u, v, w, vu, wv in fis.direction_mf:
        if x <= v:
            mg = 1.0 if u == v else (x - u) / vu if x > u else 0.0
        else:
            mg = 1.0 if v == w else (w - x) / wv if x < w else 0.0
        if mg > 0.0:
            row = table[b]
            for a, md in mu_d:
                fire = mg * md  # B_ab, eq. 9
                num += fire * row[a]
                den += fire
    if den == 0.0:
        raise ValueError(f"no rule fires for d={d}, phi={phi}: the input sets do not cover it")
    return num / den


def relative_direction(pos: Vec2, vel: Vec2, goal: Vec2, obstacle: Vec2, params: FSFMParams = DEFAULT) -> float:
    """phi = wrap(gamma - front) [rad], with gamma from eq. 14 and front from eq. 13 (or the velocity)."""
    vx, vy = vel
    if params.front == "velocity" and math.hypot(vx, vy) >= params.min_speed_for_front:
        front = math.atan2(vy, vx)
    else:
        front = math.atan2(goal[1] - pos[1], goal[0] - pos[0])  # eq. 13
    gamma = math.atan2(obstacle[1] - pos[1], obstacle[0] - pos[0])  # eq. 14
    return wrap_angle(gamma - front)


def obstacle_gains(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: FSFMParams = DEFAULT,
) -> list[float]:
    """The FIS gain k_j of every obstacle (eq. 8-14), in the order given."""
    p, v, g = xy(pos), xy(vel), xy(goal)
    return [
        gain(math.hypot(o[0] - p[0], o[1] - p[1]), relative_direction(p, v, g, o, params), params.fis)
        for o in points(obstacles)
    ]


def navigation_force(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: FSFMParams = DEFAULT,
) -> Vec2:
    """Eq. 3 with each obstacle's k from the FIS: F^n [N]."""
    x, y = xy(pos)
    vx, vy = xy(vel)
    gx, gy = xy(goal)
    sfm = params.sfm
    fx, fy = goal_force((x, y), (vx, vy), (gx, gy), sfm)
    r_ij, sigma, cutoff, fis = sfm.r_ij, sfm.sigma, sfm.cutoff_distance, params.fis
    if params.front == "velocity" and math.hypot(vx, vy) >= params.min_speed_for_front:
        front = math.atan2(vy, vx)
    else:
        front = math.atan2(gy - y, gx - x)  # beta, eq. 13
    atan2, exp, hypot, remainder = math.atan2, math.exp, math.hypot, math.remainder
    for ox, oy in points(obstacles):
        dx, dy = x - ox, y - oy  # along e_ij
        d = hypot(dx, dy)  # eq. 12
        if d < EPS_DISTANCE or d > cutoff:
            continue
        phi = remainder(atan2(-dy, -dx) - front, _TAU)  # gamma (eq. 14) relative to the front
        k = gain(d, phi, fis)  # eq. 8-10
        overlap = r_ij - d
        c = k * (exp(overlap / sigma) + (overlap if overlap > 0.0 else 0.0)) / d  # eq. 5-7
        fx += c * dx
        fy += c * dy
    return fx, fy


def step(
    pos: Sequence[float],
    vel: Sequence[float],
    goal: Sequence[float],
    obstacles: Sequence[Sequence[float]],
    params: FSFMParams = DEFAULT,
) -> Vec2:
    """Navigator contract (see :mod:`arena.navigation.base`): SFM with FIS-adapted gains,
    `command_velocity` of `navigation_force`.

    With the paper's Ruspini partitions this runs flattened (it runs per robot and tick): `xy`, `points`,
    `goal_force`, `command_velocity` and `clip_speed` inlined on the constants `FSFMParams.flat`, `gain` as
    `_partition_gain`, each the very float operations of what it stands for, in the same order.
    """
    flat = params.flat  # type: ignore[attr-defined]
    if flat is None:
        v = xy(vel)
        return command_velocity(v, navigation_force(pos, v, goal, obstacles, params), params.sfm)
    c_goal, v0, r_ij, sigma, cutoff, tau_m, integrate, velocity_front, min_speed, dist, dirn, table = flat
    x, y = float(pos[0]), float(pos[1])
    vx, vy = float(vel[0]), float(vel[1])
    gx, gy = float(goal[0]), float(goal[1])
    ex, ey = gx - x, gy - y  # eq. 4, `goal_force`
    dg = hypot(ex, ey)
    if dg < EPS_DISTANCE:
        ex = ey = 0.0
    else:
        ex, ey = ex / dg, ey / dg
    fx, fy = c_goal * (v0 * ex - vx), c_goal * (v0 * ey - vy)
    if velocity_front and hypot(vx, vy) >= min_speed:
        front = atan2(vy, vx)
    else:
        front = atan2(gy - y, gx - x)  # beta, eq. 13
    for o in obstacles if type(obstacles) is list else points(obstacles):
        dx, dy = x - float(o[0]), y - float(o[1])  # along e_ij
        d = hypot(dx, dy)  # eq. 12
        if d < EPS_DISTANCE or d > cutoff:
            continue
        phi = remainder(atan2(-dy, -dx) - front, _TAU)  # gamma (eq. 14) relative to the front
        k = _partition_gain(d, abs(phi), dist, dirn, table)  # eq. 8-10
        overlap = r_ij - d
        c = k * (exp(overlap / sigma) + (overlap if overlap > 0.0 else 0.0)) / d  # eq. 5-7
        fx += c * dx
        fy += c * dy
    fx, fy = fx * tau_m, fy * tau_m  # eq. 17-20, `command_velocity`
    if integrate:
        fx += vx
        fy += vy
    speed = hypot(fx, fy)  # `clip_speed`
    if speed > v0:
        s = v0 / speed
        return fx * s, fy * s
    return fx, fy


def _partition_gain(  # noqa: C901, PLR0912 - eq. 8-10 flattened: two inputs' neighbours, the four rules they fire
    d: float, x: float, dist: tuple, dirn: tuple, table: tuple[tuple[float, ...], ...]
) -> float:
    """`gain(d, x, fis)` for x >= 0 on Ruspini partitions (`_spans` of the distance and direction sets): each input
    has a degree in at most two neighbouring sets (a, a + 1) and (b, b + 1), found from the centres; the same
    degrees, products and sums in the same order as `gain`, which tries every set."""
    first, last, spans = dist
    if d <= first:
        a, da, da1 = 0, 1.0, 0.0
    elif not d <= last:  # beyond the last centre (or NaN): the right shoulder alone
        a, da, da1 = len(spans), 1.0, 0.0
    else:
        for a, (w, wv, u, vu) in enumerate(spans):  # noqa: B007 - the span found is used below
            if d <= w:
                break
        da, da1 = (w - d) / wv, (d - u) / vu
    first, last, spans = dirn
    if x <= first:
        b, gb, gb1 = 0, 1.0, 0.0
    elif not x <= last:
        b, gb, gb1 = len(spans), 1.0, 0.0
    else:
        for b, (w, wv, u, vu) in enumerate(spans):  # noqa: B007
            if x <= w:
                break
        gb, gb1 = (w - x) / wv, (x - u) / vu
    num = den = 0.0
    if gb > 0.0:  # direction set b, then b + 1; in each, distance set a, then a + 1
        row = table[b]
        if da > 0.0:
            fire = gb * da  # B_ab, eq. 9
            num += fire * row[a]
            den += fire
        if da1 > 0.0:
            fire = gb * da1
            num += fire * row[a + 1]
            den += fire
    if gb1 > 0.0:
        row = table[b + 1]
        if da > 0.0:
            fire = gb1 * da
            num += fire * row[a]
            den += fire
        if da1 > 0.0:
            fire = gb1 * da1
            num += fire * row[a + 1]
            den += fire
    if den == 0.0:
        raise ValueError(f"no rule fires for d={d}, phi={x}: the input sets do not cover it")
    return num / den
