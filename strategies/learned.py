"""A learned policy as a robot brain: observation, action and policy file (numpy only).

What a learning environment (`arena.learn`) and a deployed robot process share,
so that a policy trained in one process plays unchanged as a robot process:

* `observe(sense, order, view)`: what the robot itself receives at tick k (its
  `Sense` of tick k - L and its base station's latest `Order`, which carries the
  referee's command) as one flat float32 vector; `OBS_FIELDS` documents it;
* `to_cmd(tick, action, view)`: an action, a `Box` vector (vx, vy, omega, kick)
  in [-1, 1] or an index into `DISCRETE`, as the robot's `Cmd`;
* `LearnerBrain`: a `RobotBrain` that asks a `decide(tick, sense, order)` for an
  action every `frame_skip` ticks and holds it in between;
* a policy file (`save_policy`, `load_policy`): a pickle of the policy per robot
  number, the strategy that plays the rest of the team, and the action form. The
  strategy name `policy:PATH` (`policy_strategy`) plays it in `arena match`,
  `arena tournament` and `arena run robot`.

Every coordinate is in the robot's attack frame: the opponent goal is at +x
whichever side the team plays on, so one policy serves both halves and teams.
"""

from __future__ import annotations

import math
import pickle
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any, get_args

import numpy as np

from arena.runtime.config import ConfigError, MatchConfig
from arena.schemas.messages import Cmd, Order, Report, Sense
from arena.schemas.vocabulary import RefCommandName
from arena.strategies.base import RobotContext, Strategy, TeamContext, report_of

PREFIX = "policy:"
COMMANDS: tuple[str, ...] = get_args(RefCommandName)
ROLES = ("goalkeeper", "defender", "attacker")
MAX_AGE = 60.0  # [s] ages are clipped here


def slots(robots: int) -> int:
    """Robot detections in an observation: every other robot on the field."""
    return 2 * robots - 1


def obs_fields(robots: int) -> list[tuple[str, int, float, float, str]]:
    """(name, size, low, high, meaning) of every part of the flat observation, in order."""
    return [
        (
            "self",
            7,
            -2.0,
            2.0,
            "x/half_length, y/half_width, cos theta, sin theta (attack frame); "
            "vx, vy (body frame) / max_speed, omega / max_omega: own odometry",
        ),
        (
            "ball",
            7,
            -30.0,
            30.0,
            "sense: visible (0/1), x/half_length, y/half_width (attack frame), "
            "forward, left [m] (body frame), distance [m], has_ball (0/1); zeros but has_ball when not visible",
        ),
        ("goal", 2, -30.0, 30.0, "the opponent goal's centre, forward and left [m] in the body frame"),
        (
            "team_ball",
            4,
            -2.0,
            MAX_AGE,
            "order: ball_valid (0/1), x/half_length, y/half_width (attack frame), "
            "age [s] (the base station's fused ball)",
        ),
        (
            "robots",
            4 * slots(robots),
            -30.0,
            30.0,
            f"{slots(robots)} slots, nearest first: present (0/1), "
            "+1 own team / -1 opponent, forward, left [m] (body frame); absent slots are zeros",
        ),
        (
            "referee",
            len(COMMANDS) + 5,
            -2.0,
            2.0,
            "order: the command in force one-hot over "
            f"{', '.join(COMMANDS)}; then for us, for them, for both (one-hot); spot x/half_length, "
            "spot y/half_width (attack frame)",
        ),
        ("role", len(ROLES) + 1, 0.0, 1.0, f"order: role one-hot over {', '.join(ROLES)}, other"),
    ]


@dataclass(frozen=True)
class View:
    """What `observe` and `to_cmd` need of a robot's configuration, worked out once."""

    team: str
    robots: int
    half_length: float  # [m]
    half_width: float  # [m]
    max_speed: float  # [m/s]
    max_omega: float  # [rad/s]
    kick_max_speed: float  # [m/s]
    dt: float  # [s] control tick
    low: np.ndarray = field(repr=False, compare=False, default=None)  # type: ignore[assignment]
    high: np.ndarray = field(repr=False, compare=False, default=None)  # type: ignore[assignment]

    @classmethod
    def of(cls, cfg: MatchConfig, team: str, robots: int = 0) -> View:
        """`robots`: the team size the observation is shaped for (its robot slots); 0: the match's."""
        robots = robots or cfg.robots
        fields = obs_fields(robots)
        low = np.concatenate([np.full(n, lo, np.float32) for _, n, lo, _, _ in fields])
        high = np.concatenate([np.full(n, hi, np.float32) for _, n, _, hi, _ in fields])
        r = cfg.robot
        return cls(
            team,
            robots,
            cfg.field.length / 2,
            cfg.field.width / 2,
            r.max_speed,
            r.max_omega,
            r.kick_max_speed,
            cfg.timing.dt,
            low,
            high,
        )

    @property
    def size(self) -> int:
        return len(self.low)


def observe(sense: Sense | None, order: Order | None, v: View) -> np.ndarray:
    """The flat observation (float32, `obs_fields` order) of what the robot received."""
    s = order.attack_dir if order is not None else (1 if v.team == "a" else -1)
    hl, hw = v.half_length, v.half_width
    out: list[float] = []
    if sense is None:
        px = py = th = 0.0
        out += [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    else:
        p = sense.pose
        px, py, th = p.x, p.y, p.theta
        out += [
            s * px / hl,
            s * py / hw,
            s * math.cos(th),
            s * math.sin(th),
            sense.vx / v.max_speed,
            sense.vy / v.max_speed,
            sense.omega / v.max_omega,
        ]
    c, sn = math.cos(th), math.sin(th)
    b = sense.ball if sense is not None else None
    if b is not None and b.visible:
        dx, dy = b.x - px, b.y - py
        out += [1.0, s * b.x / hl, s * b.y / hw, c * dx + sn * dy, -sn * dx + c * dy, math.hypot(dx, dy)]
    else:
        out += [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    out.append(1.0 if sense is not None and sense.has_ball else 0.0)
    gx, gy = s * hl - px, -py
    out += [c * gx + sn * gy, -sn * gx + c * gy]
    if order is not None and order.ball_valid:
        out += [1.0, s * order.ball_x / hl, s * order.ball_y / hw, min(order.ball_age * v.dt, MAX_AGE)]
    else:
        out += [0.0, 0.0, 0.0, 0.0]
    n = slots(v.robots)
    seen = []
    if sense is not None:
        for r in sense.robots:
            dx, dy = r.x - px, r.y - py
            seen.append((dx * dx + dy * dy, 1.0 if r.team == v.team else -1.0, c * dx + sn * dy, -sn * dx + c * dy))
        seen.sort()
    for _d2, side, fwd, left in seen[:n]:
        out += [1.0, side, fwd, left]
    out += [0.0] * (4 * (n - min(n, len(seen))))
    cmd = [0.0] * (len(COMMANDS) + 3)
    role = [0.0] * (len(ROLES) + 1)
    if order is not None:
        cmd[COMMANDS.index(order.command)] = 1.0
        ct = order.command_team
        cmd[len(COMMANDS) + (0 if ct == v.team else 2 if ct == "" else 1)] = 1.0
        out += cmd
        out += [s * order.spot_x / hl, s * order.spot_y / hw]
        role[ROLES.index(order.role) if order.role in ROLES else len(ROLES)] = 1.0
    else:
        cmd[COMMANDS.index("STOP")] = 1.0
        cmd[len(COMMANDS) + 2] = 1.0
        out += cmd
        out += [0.0, 0.0]
        role[len(ROLES)] = 1.0
    out += role
    return np.clip(np.array(out, dtype=np.float32), v.low, v.high)


# The discrete actions: (vx, vy, omega, kick) as fractions of the Box's scales.
DISCRETE: tuple[tuple[str, tuple[float, float, float, float]], ...] = (
    ("stop", (0.0, 0.0, 0.0, 0.0)),
    ("forward", (0.4, 0.0, 0.0, 0.0)),
    ("backward", (-0.4, 0.0, 0.0, 0.0)),
    ("left", (0.0, 0.4, 0.0, 0.0)),
    ("right", (0.0, -0.4, 0.0, 0.0)),
    ("forward-left", (0.3, 0.3, 0.0, 0.0)),
    ("forward-right", (0.3, -0.3, 0.0, 0.0)),
    ("turn-left", (0.0, 0.0, 0.5, 0.0)),
    ("turn-right", (0.0, 0.0, -0.5, 0.0)),
    ("kick", (0.2, 0.0, 0.0, 1.0)),
)


def to_cmd(tick: int, action: Any, v: View, discrete: bool = False) -> Cmd:
    """The `Cmd` for an action: vx, vy [m/s] = a0, a1 x max_speed (body frame), omega = a2 x max_omega,
    kick_speed = max(0, a3) x kick_max_speed; each clipped to [-1, 1] first. The dribbler is always on."""
    a = DISCRETE[int(action)][1] if discrete else action
    if isinstance(a, np.ndarray):
        a = a.tolist()  # Python floats, exactly the array's values (float32 widens without rounding)
    vx = min(1.0, max(-1.0, float(a[0])))
    vy = min(1.0, max(-1.0, float(a[1])))
    om = min(1.0, max(-1.0, float(a[2])))
    kick = min(1.0, max(-1.0, float(a[3])))
    return Cmd(
        tick=tick,
        vx=vx * v.max_speed,
        vy=vy * v.max_speed,
        omega=om * v.max_omega,
        dribbler=True,
        kick_speed=max(0.0, kick) * v.kick_max_speed,
    )


Decide = Callable[[int, "Sense | None", "Order | None"], Any]


class LearnerBrain:
    """A `RobotBrain` whose action comes from `decide(tick, sense, order)` every `frame_skip` ticks."""

    def __init__(self, ctx: RobotContext, decide: Decide, frame_skip: int = 1, discrete: bool = False):
        self.n = ctx.n
        self.view = View.of(ctx.cfg, ctx.team)
        self.decide = decide
        self.frame_skip = frame_skip
        self.discrete = discrete
        self.action: Any = 0 if discrete else (0.0, 0.0, 0.0, 0.0)
        self.role = ""

    def step(self, tick: int, sense: Sense | None, order: Order | None) -> Cmd:
        if order is not None:
            self.role = order.role
        if tick % self.frame_skip == 0:
            self.action = self.decide(tick, sense, order)
        return to_cmd(tick, self.action, self.view, self.discrete)

    def report(self, tick: int, sense: Sense | None) -> Report:
        return report_of(tick, self.n, sense, self.role)


# ------------------------------------------------------------------ policies
class LinearPolicy:
    """action = tanh(W obs + b): a Box action from a flat observation."""

    def __init__(self, weights: np.ndarray, bias: np.ndarray):
        self.weights = np.asarray(weights, dtype=np.float64)
        self.bias = np.asarray(bias, dtype=np.float64)

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return np.tanh(self.weights @ obs + self.bias).astype(np.float32)


class RecordedActions:
    """Plays recorded actions in order, one per call (replays an episode; zeros once they run out)."""

    def __init__(self, actions: Sequence[Any]):
        self.actions = [np.asarray(a) for a in actions]
        self.i = 0

    def __call__(self, obs: np.ndarray) -> Any:
        a = self.actions[self.i] if self.i < len(self.actions) else np.zeros_like(self.actions[0])
        self.i += 1
        return a


@dataclass
class PolicyFile:
    """What a policy file holds: a policy (obs -> action) per robot number, and how it plays."""

    base: str  # the strategy of the team brain and of every robot without a policy
    policies: dict[int, Callable[[np.ndarray], Any]]
    frame_skip: int = 1
    discrete: bool = False
    robots: int = 0  # the team size it was trained with: its observations have that many robot slots (0: any)


def save_policy(
    path: str | Path,
    policies: dict[int, Callable[[np.ndarray], Any]],
    base: str,
    frame_skip: int = 1,
    discrete: bool = False,
    robots: int = 0,
) -> Path:
    """Write a policy file: `policies` maps robot numbers to picklable callables obs -> action.

    `robots`: the team size it was trained with, so that a match of another size still gives it
    observations of the size it knows (the nearest robots fill the slots)."""
    p = Path(path)
    p.write_bytes(pickle.dumps(PolicyFile(base, dict(policies), frame_skip, discrete, robots)))
    return p


def load_policy(path: str | Path) -> PolicyFile:
    """Read a policy file; ConfigError (one line) if it cannot be."""
    try:
        data = pickle.loads(Path(path).read_bytes())
    except FileNotFoundError:
        raise ConfigError(f"policy file {path} not found") from None
    except IsADirectoryError:
        raise ConfigError(f"policy file {path} is a directory: give the file save_policy wrote") from None
    except Exception as exc:  # anything a file that is not a pickle of ours makes pickle raise
        raise ConfigError(f"policy file {path} cannot be read: {type(exc).__name__}: {exc}") from None
    if not isinstance(data, PolicyFile):
        raise ConfigError(f"policy file {path} is not an arena policy (write it with arena.learn.save_policy)")
    return data


@cache
def policy_strategy(name: str) -> Strategy:
    """The strategy `policy:PATH`: the file's policies play their robots, its `base` the rest."""
    from arena.strategies import registry

    path = name[len(PREFIX) :]
    pf = load_policy(path)
    base = registry.get(pf.base)

    def make_robot(ctx: RobotContext):
        if ctx.n not in pf.policies:
            return base.make_robot(ctx)
        policy = load_policy(path).policies[ctx.n]  # a fresh copy per robot: policies may keep state
        view = View.of(ctx.cfg, ctx.team, pf.robots)
        return LearnerBrain(
            ctx, lambda _k, sense, order: policy(observe(sense, order, view)), pf.frame_skip, pf.discrete
        )

    def make_team(ctx: TeamContext):
        return base.make_team(ctx)

    return Strategy(
        name=name,
        make_team=make_team,
        make_robot=make_robot,
        description=f"learned policy for robots {sorted(pf.policies)}, the rest by {base.name}",
    )
