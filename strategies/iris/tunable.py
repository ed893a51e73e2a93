"""The IRIS strategies' tunable parameters (`Strategy.params`) and how a team's values replace `IrisParams`.

Every entry is a field of `IrisParams` (or of its `skills` and `fusion`
parts, `NESTED`) with the same default, so a match with no values given plays
the very `IrisParams` object of the strategy, as before. The ranges are those
the robot and the field allow, not a guess at the best: speeds up to what the
drive (5 m/s) and the kicker (`robot.kick_max_speed`, 8 m/s) give, distances
within the 12 m x 8 m field, the push guard below the 1.5 m/s pushing foul.

Paper 2 gives none of the goalkeeper's numbers nor the kick speed ("the speed
of movement of the robot and the kick on goal is made the same for all the
algorithms", no figure): `kick_speed` (the kicker), and `keeper_depth`,
`keeper_post_margin`, `intercept_min_speed`, `keeper_gain`,
`ball_vel_smoothing` and `max_ball_speed` (the keeper and the ball velocity
it intercepts with, docs/strategies.md) are the model's unknowns; `KEEPER` and
`KICKER` name them. The paper's own numbers (the 1 m area overlap) are
declared too, for a study of how much a result depends on them.
"""

from __future__ import annotations

import dataclasses

from arena.navigation import PARAMS as NAVIGATORS
from arena.strategies.base import Param
from arena.strategies.iris.params import IrisParams

_D = IrisParams()


def _p(name: str, low: float, high: float, unit: str, meaning: str, default: float | None = None) -> Param:
    part, field = NESTED.get(name, ("", name))
    value = getattr(getattr(_D, part) if part else _D, field) if default is None else default
    return Param(name=name, default=value, low=low, high=high, unit=unit, meaning=meaning)


# name -> (IrisParams part, field) for the parameters that live in `skills` and `fusion`
NESTED = {
    "keeper_depth": ("skills", "keeper_depth"),
    "keeper_post_margin": ("skills", "keeper_post_margin"),
    "intercept_min_speed": ("skills", "intercept_min_speed"),
    "ball_vel_smoothing": ("fusion", "vel_smoothing"),
    "max_ball_speed": ("fusion", "max_ball_speed"),
}

KICKER = ("kick_speed",)
KEEPER = (
    "keeper_depth",
    "keeper_post_margin",
    "intercept_min_speed",
    "keeper_gain",
    "ball_vel_smoothing",
    "max_ball_speed",
)

PARAMS: tuple[Param, ...] = (
    _p(
        "kick_speed",
        2.0,
        8.0,
        "m/s",
        "shot speed, the kicker's full power (not in paper 2); at most robot.kick_max_speed",
    ),
    _p("keeper_depth", 0.1, 1.0, "m", "goalkeeper: its line in front of the goal line (not in paper 2)"),
    _p("keeper_post_margin", 0.0, 0.5, "m", "goalkeeper: stays this far inside the posts (not in paper 2)"),
    _p(
        "intercept_min_speed",
        0.1,
        3.0,
        "m/s",
        "goalkeeper: intercepts a ball this fast towards the goal (not in paper 2)",
    ),
    _p(
        "keeper_gain",
        0.0,
        10.0,
        "1/s",
        "goalkeeper: drives at this speed per metre to go; 0: 1 m/s per metre (not in paper 2)",
    ),
    _p(
        "ball_vel_smoothing",
        0.05,
        1.0,
        "",
        "weight of the newest ball velocity sample, the keeper's interception input",
    ),
    _p(
        "max_ball_speed", 5.0, 30.0, "m/s", "a faster jump between ball estimates is noise and resets the ball velocity"
    ),
    _p("cruise", 1.0, 4.5, "m/s", "travel speed (the drive gives 5)"),
    _p("dribble_speed", 0.5, 2.5, "m/s", "speed while holding the ball"),
    _p("approach_speed", 0.5, 3.0, "m/s", "final approach onto the ball"),
    _p("basic_shoot_distance", 2.0, 8.0, "m", "basic: kick from this distance to the goal centre"),
    _p("advance_shoot_distance", 2.0, 8.0, "m", "advance: shoot within this distance if the line is clear"),
    _p("close_shot", 0.5, 3.0, "m", "advance: shoot anyway this close"),
    _p("pass_arrive", 0.5, 3.0, "m/s", "ball speed at the receiver of a pass"),
    _p("aim_tolerance", 0.025, 0.3, "rad", "largest heading error at which a shot or pass is taken"),
    _p("shot_spread", 0.05, 0.5, "m", "a shot is taken when the ball would pass this close to the aim point"),
    _p("chase_hysteresis", 0.0, 1.5, "m", "the current chaser counts this much nearer the ball"),
    _p("possession_radius", 0.2, 1.0, "m", "an opponent this close to the ball has it"),
    _p("max_hold", 0.5, 6.0, "s", "advance: act after holding the ball this long"),
    _p("carry_limit", 0.5, 2.8, "m", "release the ball before this straight carry (the rules' limit is 3 m)"),
    _p("cover_depth", -5.0, 0.0, "m", "the defender's place along the attack direction while the team attacks"),
    _p("mark_zone", 3.0, 10.0, "m", "advance defense: an opponent this close to our goal is marked"),
    _p("block_zone", 3.0, 10.0, "m", "advance defense: a carrier this close to our goal is blocked"),
    _p("block_gain", 0.5, 8.0, "1/s", "advance defense: the blocker's speed per metre off the kick line"),
    _p("drop_back", 2.0, 8.0, "m", "advance defense: with the ball this close to our goal the attacker marks too"),
    _p("take_angle", 0.1, 1.5, "rad", "advance defense: the blocker takes the ball only this close to the kick line"),
    _p("pressure_range", 0.5, 3.0, "m", "advance attack: a blocker this close leaves no room to go round it"),
    _p("shot_commit", 0.1, 2.0, "s", "advance attack: a clear shot seen is taken within this time"),
    _p("push_guard", 0.0, 1.4, "m/s", "closing speed at contact with an opponent (pushing fouls above 1.5)"),
    _p("overlap", 0.0, 3.0, "m", "defender and attacker areas overlap (paper 2: 1 m)"),
    Param(
        name="navigator",
        default=_D.navigator,
        choices=tuple(NAVIGATORS),
        meaning="the local navigator every motion goes through (docs/navigation.md)",
    ),
)


ADVANCE_ONLY = frozenset(
    {
        "advance_shoot_distance",
        "close_shot",
        "max_hold",
        "mark_zone",
        "block_zone",
        "block_gain",
        "drop_back",
        "take_angle",
        "pressure_range",
        "shot_commit",
    }
)
BASIC_ONLY = frozenset({"basic_shoot_distance"})


def params_for(advance: bool) -> tuple[Param, ...]:
    """What the basic or the advance play declares: the parameters it reads."""
    other = BASIC_ONLY if advance else ADVANCE_ONLY
    return tuple(p for p in PARAMS if p.name not in other)


def tuned(base: IrisParams, values: dict) -> IrisParams:
    """`base` with the team's checked `values` (name -> value of `PARAMS`); `base` itself for none."""
    if not values:
        return base
    flat = {k: v for k, v in values.items() if k not in NESTED}
    parts: dict[str, dict] = {}
    for name, (part, field) in NESTED.items():
        if name in values:
            parts.setdefault(part, {})[field] = values[name]
    for part, changes in parts.items():
        flat[part] = dataclasses.replace(getattr(base, part), **changes)
    return dataclasses.replace(base, **flat)
