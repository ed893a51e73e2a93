"""The strategy conformance suite: checks any `Strategy`, built-in or a user's plugin.

Like Gymnasium's ``api_test``/``seed_test``, every check is a plain function
that raises `AssertionError` with a readable message, so that a plugin's own
tests can run them::

    from arena.strategies import conformance
    conformance.check_all(my_strategy)

`check_all` runs every check below over a short scripted match with no
transport (`scripted_inputs`): teams fed synthetic reports and referee frames,
robots fed synthetic senses and the team's orders.

* `check_orders`: one `Order` per robot number, stamped with the tick, valid
  against the wire schema;
* `check_commands`: every `Cmd` stamped with the tick, finite and within the
  robot's limits (speed, turn rate, kick speed), valid against the schema;
* `check_reports`: every `Report` stamped, for the right robot, valid;
* `check_stop`: under STOP (and HALT-like commands) robots do not move;
* `check_missing_inputs`: sense=None and order=None are handled;
* `check_deterministic`: two instances built with the same seed produce the
  same orders and commands at every step (the failure names the first step);
* `check_params`: the declared parameters (`Strategy.params`) are well formed
  (unique names, a type of bool, int, float or str, the default within the
  range), every default given explicitly plays as giving none, and with every
  parameter at the bottom and then at the top of its range the commands are
  still valid (`check_commands`).
"""

from __future__ import annotations

import math
import random

import msgspec

from arena.config import MatchConfig
from arena.schemas.messages import BallSeen, Cmd, Order, Pose, Referee, Report, RobotSeen, Sense, decoder, encode
from arena.strategies.base import Param, RobotContext, Strategy, TeamContext

STOP_LIKE = ("STOP", "HALT", "END_GAME", "HALF_TIME")
STEPS = 60  # [ticks] of the scripted match


def _roundtrip(msg, kind: type):
    try:
        return decoder(kind).decode(encode(msg))
    except (msgspec.DecodeError, msgspec.ValidationError) as exc:
        raise AssertionError(f"{kind.__name__} does not validate against the wire schema: {exc}") from None


def scripted_inputs(cfg: MatchConfig, seed: int, command: str = "START"):
    """Per tick: (referee frame, {team: {n: Sense}}) for a short synthetic match.

    Robots stand on a fixed formation with a little seeded jitter, the ball rolls
    across the field; every robot sees the ball and everyone within range.
    """
    rng = random.Random(seed)
    half = cfg.field.length / 2
    base = {("a", n): (-half + 0.5 + 2.0 * n, 0.8 * n - 0.8) for n in range(cfg.robots)}
    base.update({("b", n): (half - 0.5 - 2.0 * n, 0.8 - 0.8 * n) for n in range(cfg.robots)})
    for k in range(STEPS):
        ball = (-2.0 + 0.08 * k, 1.0 - 0.03 * k)
        ref = Referee(tick=k, stage="FIRST_HALF", command=command if k >= 5 else "KICKOFF", command_team="a")
        senses: dict[str, dict[int, Sense]] = {"a": {}, "b": {}}
        pos = {key: (x + rng.gauss(0, 0.02), y + rng.gauss(0, 0.02)) for key, (x, y) in base.items()}
        for (team, n), (x, y) in pos.items():
            theta = 0.0 if team == "a" else math.pi
            seen = [RobotSeen(team=t, x=px, y=py) for (t, m), (px, py) in pos.items() if (t, m) != (team, n)]
            senses[team][n] = Sense(
                tick=k,
                pose=Pose(x=x, y=y, theta=theta),
                ball=BallSeen(visible=True, x=ball[0], y=ball[1]),
                robots=seen,
                has_ball=False,
            )
        yield ref, senses


def run_script(strategy: Strategy, cfg: MatchConfig, seed: int, command: str = "START"):
    """Play the scripted inputs through fresh brains. Returns [(tick, orders by team, cmds by team, reports)]."""
    teams = {t: strategy.make_team(TeamContext(cfg=cfg, team=t, rng=random.Random(seed))) for t in ("a", "b")}
    robots = {
        (t, n): strategy.make_robot(RobotContext(cfg=cfg, team=t, n=n, rng=random.Random(seed * 31 + n)))
        for t in ("a", "b")
        for n in range(cfg.robots)
    }
    comm = cfg.timing.comm_period
    orders: dict[str, dict[int, Order]] = {"a": {}, "b": {}}
    reports: dict[str, dict[int, Report]] = {"a": {}, "b": {}}
    out = []
    for ref, senses in scripted_inputs(cfg, seed, command):
        k = ref.tick
        step_orders = {}
        if k % comm == 1 % comm:
            for t, brain in teams.items():
                orders[t] = brain.step(k, reports[t], ref)
                step_orders[t] = orders[t]
            reports = {"a": {}, "b": {}}
        cmds: dict[str, dict[int, Cmd]] = {"a": {}, "b": {}}
        step_reports: dict[str, dict[int, Report]] = {"a": {}, "b": {}}
        for (t, n), brain in robots.items():
            cmds[t][n] = brain.step(k, senses[t][n], orders[t].get(n))
            if k % comm == 0:
                rep = brain.report(k, senses[t][n])
                reports[t][n] = rep
                step_reports[t][n] = rep
        out.append((k, step_orders, cmds, step_reports))
    return out


def check_orders(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    for k, orders, _, _ in run_script(strategy, cfg, seed):
        for team, by_robot in orders.items():
            assert sorted(by_robot) == list(range(cfg.robots)), f"tick {k}: team {team} orders for {sorted(by_robot)}"
            for n, o in by_robot.items():
                assert isinstance(o, Order), f"tick {k}: order for {team}/{n} is a {type(o).__name__}"
                assert o.tick == k and o.robot == n, (
                    f"tick {k}: order for {team}/{n} stamped tick {o.tick} robot {o.robot}"
                )
                _roundtrip(o, Order)


def check_commands(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    r = cfg.robot
    for k, _, cmds, _ in run_script(strategy, cfg, seed):
        for team, by_robot in cmds.items():
            for n, c in by_robot.items():
                where = f"tick {k}: {team}/{n}"
                assert isinstance(c, Cmd), f"{where}: command is a {type(c).__name__}"
                assert c.tick == k, f"{where}: command stamped {c.tick}"
                values = (c.vx, c.vy, c.omega, c.kick_speed, *c.wheels)
                assert all(math.isfinite(v) for v in values), f"{where}: non-finite command {c}"
                assert math.hypot(c.vx, c.vy) <= r.max_speed + 1e-9, f"{where}: speed {math.hypot(c.vx, c.vy):.2f} m/s"
                assert abs(c.omega) <= r.max_omega + 1e-9, f"{where}: turn rate {c.omega:.2f} rad/s"
                assert 0.0 <= c.kick_speed <= r.kick_max_speed + 1e-9, f"{where}: kick speed {c.kick_speed}"
                _roundtrip(c, Cmd)


def check_reports(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    for k, _, _, reports in run_script(strategy, cfg, seed):
        for team, by_robot in reports.items():
            for n, rep in by_robot.items():
                assert isinstance(rep, Report), f"tick {k}: report of {team}/{n} is a {type(rep).__name__}"
                assert rep.tick == k and rep.robot == n, (
                    f"tick {k}: report of {team}/{n} stamped {rep.tick}/{rep.robot}"
                )
                _roundtrip(rep, Report)


def check_stop(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    for command in STOP_LIKE:
        for k, _, cmds, _ in run_script(strategy, cfg, seed, command=command):
            if k < 5 + 2 * cfg.timing.comm_period:  # the command reaches the robots with the next order
                continue
            for team, by_robot in cmds.items():
                for n, c in by_robot.items():
                    moving = abs(c.vx) + abs(c.vy) + abs(c.omega) > 1e-9 or c.kick_speed > 0 or c.wheels
                    assert not moving, f"tick {k}: {team}/{n} moves under {command}: {c}"


def check_missing_inputs(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    team = strategy.make_team(TeamContext(cfg=cfg, team="a", rng=random.Random(seed)))
    orders = team.step(1, {}, None)
    assert sorted(orders) == list(range(cfg.robots)), "team brain with no reports and no referee"
    for n in range(cfg.robots):
        robot = strategy.make_robot(RobotContext(cfg=cfg, team="a", n=n, rng=random.Random(seed)))
        for k, order in ((0, None), (1, orders[n]), (2, None)):
            c = robot.step(k, None, order)
            assert isinstance(c, Cmd) and c.tick == k, f"robot {n}: step({k}, None, {type(order).__name__})"
            rep = robot.report(k, None)
            assert isinstance(rep, Report) and rep.tick == k and rep.robot == n, f"robot {n}: report({k}, None)"
            _roundtrip(rep, Report)


def check_deterministic(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    first = run_script(strategy, cfg, seed)
    second = run_script(strategy, cfg, seed)
    for (k, o1, c1, r1), (_, o2, c2, r2) in zip(first, second):
        for name, x, y in (("orders", o1, o2), ("commands", c1, c2), ("reports", r1, r2)):
            ex = {t: {n: encode(m) for n, m in v.items()} for t, v in x.items()}
            ey = {t: {n: encode(m) for n, m in v.items()} for t, v in y.items()}
            assert ex == ey, f"tick {k}: {name} differ between two runs with seed {seed}"


def _declaration(p: Param) -> None:
    where = f"parameter {p.name!r}"
    assert isinstance(p, Param), f"{where} is a {type(p).__name__}, not an arena Param"
    assert p.name.isidentifier(), f"{where}: the name must be an identifier (a TOML key)"
    assert p.type in ("bool", "int", "float", "str"), f"{where}: default {p.default!r} is not bool, int, float or str"
    assert p.meaning, f"{where}: no meaning given"
    if p.type in ("int", "float"):
        assert p.low is not None and p.high is not None, f"{where}: a number needs low and high"
        assert p.low <= p.default <= p.high, f"{where}: default {p.default} outside {p.low}..{p.high}"  # type: ignore[operator]
    else:
        assert p.low is None and p.high is None, f"{where}: only numbers have low and high"
    if p.choices:
        assert p.type == "str" and p.default in p.choices, f"{where}: default {p.default!r} not in {p.choices}"


def _extreme(p: Param, top: bool):
    if p.type == "int":
        return int(p.high if top else p.low)  # type: ignore[arg-type]
    if p.type == "float":
        return float(p.high if top else p.low)  # type: ignore[arg-type]
    if p.type == "bool":
        return top
    return p.choices[-1 if top else 0] if p.choices else p.default


def check_params(strategy: Strategy, cfg: MatchConfig, seed: int = 1) -> None:
    names = [p.name for p in strategy.params]
    assert len(set(names)) == len(names), (
        f"parameters declared twice: {sorted({n for n in names if names.count(n) > 1})}"
    )
    for p in strategy.params:
        _declaration(p)
    if not strategy.params:
        return
    defaults = {p.name: p.default for p in strategy.params}
    plain = run_script(strategy, cfg, seed)
    given = run_script(strategy, cfg.replace(params={"a": defaults, "b": defaults}), seed)
    for (k, o1, c1, _), (_, o2, c2, _) in zip(plain, given):
        for name, x, y in (("orders", o1, o2), ("commands", c1, c2)):
            ex = {t: {n: encode(m) for n, m in v.items()} for t, v in x.items()}
            ey = {t: {n: encode(m) for n, m in v.items()} for t, v in y.items()}
            assert ex == ey, f"tick {k}: {name} differ with every parameter given its default and with none given"
    for top in (False, True):
        values = {p.name: _extreme(p, top) for p in strategy.params}
        try:
            check_commands(strategy, cfg.replace(params={"a": values, "b": values}), seed)
        except AssertionError as exc:
            raise AssertionError(f"every parameter at the {'top' if top else 'bottom'} of its range: {exc}") from None


CHECKS = (
    check_orders,
    check_commands,
    check_reports,
    check_stop,
    check_missing_inputs,
    check_deterministic,
    check_params,
)


def check_all(strategy: Strategy, cfg: MatchConfig | None = None, seed: int = 1) -> None:
    """Run every check; robots = 3 and 5 cover eq. 6's odd and even splits."""
    for robots in (3, 5):
        c = (cfg or MatchConfig()).replace(robots=robots)
        for check in CHECKS:
            check(strategy, c, seed)
