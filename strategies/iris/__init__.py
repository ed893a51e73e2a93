"""The IRIS team play of paper 2: basic/advance attack and defense x static/dynamic roles.

Four strategies, registered by name (:data:`STRATEGIES`): ``basic-static``
(BS), ``basic-dynamic`` (BD), ``advance-static`` (AS), ``advance-dynamic`` (AD).
All four share robot speed and kick speed (paper 2: "the speed of movement of
the robot and the kick on goal is made the same for all the algorithms"), the
goalkeeper, the ball handling and the referee handling; they differ only in
what the paper makes them differ in: the attack and the defense of the outfield
robots (basic or advance, Fig. 7) and the role assignment (static or dynamic,
Fig. 6).

One module per concern:

* `params.py`: `IrisParams`, every number with its unit and reason;
* `tunable.py`: the numbers a team may set per match (`Strategy.params`);
* `team.py`: the base station brain `IrisTeam` (fusion, S1/S2/S3, roles);
* `robot.py`: the robot brain `IrisRobot`, its memory and the per-order plan,
  assembled from one mixin per concern:
  `motion.py` (navigation, push guard), `handling.py` (ball handling),
  `attack.py`, `defense.py`, `positions.py`, `keeper.py` and `setpieces.py`;
* `memory.py`: what a robot remembers between ticks and the plan of an order.

Cost: what depends only on the order (areas, roles, teammates, the goal
centres, a restart's fixed place) is worked out once per order (`Plan`, `support_point`,
`position_for_restart`), not once per tick; with no robot
within `obstacle_range` the navigator is not called (F-SFM then gives the
straight line at cruise speed). The per-tick path (`step`, `drive`, the
goalkeeper, the chaser) keeps its constants in attributes worked out in
`__init__` and inlines small helpers (`inside`, `S.dist`, `S.angle_to`, `min`,
the heading PID's `arena.navigation.pid.update`);
each inlined expression does the very float operations of the helper it stands
for, so that matches replay bit for bit.
"""

from __future__ import annotations

from arena.strategies.base import Strategy
from arena.strategies.iris.params import IrisParams
from arena.strategies.iris.robot import IrisRobot
from arena.strategies.iris.team import IrisTeam
from arena.strategies.iris.tunable import params_for, tuned

__all__ = ["STRATEGIES", "IrisParams", "IrisRobot", "IrisTeam"]


def _make(name: str, alias: str, advance: bool, dynamic: bool) -> Strategy:
    params = IrisParams(advance=advance, dynamic=dynamic)
    declared = params_for(advance)
    kind = (
        ("advance" if advance else "basic") + " attack and defense, " + ("dynamic" if dynamic else "static") + " roles"
    )
    # A team given no values plays `params` itself; given some, `tuned` checks them (ConfigError) and replaces.
    return Strategy(
        name=name,
        make_team=lambda ctx: IrisTeam(ctx, tuned(params, ctx.param_values(declared) if ctx.params else {})),
        make_robot=lambda ctx: IrisRobot(ctx, tuned(params, ctx.param_values(declared) if ctx.params else {})),
        aliases=(alias,),
        description=f"{kind} (paper 2)",
        params=declared,
    )


STRATEGIES = [
    _make("basic-static", "BS", advance=False, dynamic=False),
    _make("basic-dynamic", "BD", advance=False, dynamic=True),
    _make("advance-static", "AS", advance=True, dynamic=False),
    _make("advance-dynamic", "AD", advance=True, dynamic=True),
]
