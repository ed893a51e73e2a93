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
* the numpy policies `LinearPolicy` and `MLPPolicy`, which export to ONNX without
  torch, and `RecordedActions`. Policy files (ONNX) are strategies/policy_file.py.

Every coordinate is in the robot's attack frame: the opponent goal is at +x
whichever side the team plays on, so one policy serves both halves and teams.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, get_args

import numpy as np

from arena.config import MatchConfig
from arena.schemas.messages import Cmd, Order, Report, Sense
from arena.schemas.vocabulary import RefCommandName
from arena.strategies.base import POLICY_PREFIX, RobotContext, report_of

PREFIX = POLICY_PREFIX
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
    if sense is None:
        px = py = th = 0.0
        c, sn = 1.0, 0.0
        out = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    else:
        p = sense.pose
        px, py, th = p.x, p.y, p.theta
        c, sn = math.cos(th), math.sin(th)
        out = [s * px / hl, s * py / hw, s * c, s * sn, sense.vx / v.max_speed, sense.vy / v.max_speed]
        out.append(sense.omega / v.max_omega)
    b = sense.ball if sense is not None else None
    if b is not None and b.visible:
        dx, dy = b.x - px, b.y - py
        out += [1.0, s * b.x / hl, s * b.y / hw, c * dx + sn * dy, -sn * dx + c * dy, math.hypot(dx, dy)]
    else:
        out += _NO_BALL
    out.append(1.0 if sense is not None and sense.has_ball else 0.0)
    gx, gy = s * hl - px, -py
    out.append(c * gx + sn * gy)
    out.append(-sn * gx + c * gy)
    if order is not None and order.ball_valid:
        out += [1.0, s * order.ball_x / hl, s * order.ball_y / hw, min(order.ball_age * v.dt, MAX_AGE)]
    else:
        out += _NO_BALL4
    n = 2 * v.robots - 1  # slots(v.robots)
    if sense is not None and (robots := sense.robots):
        team = v.team
        seen = []
        for r in robots:
            dx, dy = r.x - px, r.y - py
            seen.append((dx * dx + dy * dy, 1.0 if r.team == team else -1.0, c * dx + sn * dy, -sn * dx + c * dy))
        seen.sort()
        for _d2, side, fwd, left in seen[:n]:
            out += (1.0, side, fwd, left)
        n -= min(n, len(seen))
    out += _EMPTY_SLOT * n
    if order is not None:
        ct = order.command_team
        out += _COMMANDS_HOT[order.command, 0 if ct == v.team else 2 if ct == "" else 1]
        out.append(s * order.spot_x / hl)
        out.append(s * order.spot_y / hw)
        out += _ROLES_HOT.get(order.role, _NO_ROLE)
    else:
        out += _NO_ORDER
    # np.clip's own arithmetic (NaN kept), without its Python wrapper: ~1 us a step less
    return np.minimum(np.maximum(np.array(out, dtype=np.float32), v.low), v.high)


_NO_BALL = (0.0,) * 6
_NO_BALL4 = (0.0,) * 4
_EMPTY_SLOT = (0.0,) * 4


def _one_hot(n: int, *hot: int) -> tuple[float, ...]:
    return tuple(1.0 if i in hot else 0.0 for i in range(n))


# The observation's one-hot parts, built once (`observe`): the referee's command and whose it is (own,
# the opponents', nobody's), and the role, the last place for none known.
_COMMANDS_HOT = {
    (c, w): _one_hot(len(COMMANDS) + 3, i, len(COMMANDS) + w) for i, c in enumerate(COMMANDS) for w in range(3)
}
_ROLES_HOT = {r: _one_hot(len(ROLES) + 1, i) for i, r in enumerate(ROLES)}
_NO_ROLE = _one_hot(len(ROLES) + 1, len(ROLES))


_NO_ORDER = _COMMANDS_HOT["STOP", 2] + (0.0, 0.0) + _NO_ROLE


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
    if discrete:
        a = DISCRETE[discrete_index(action)][1]
    else:
        a = action.tolist() if isinstance(action, np.ndarray) else action  # float32 widens without rounding
        if len(a) != 4:
            raise ValueError(f"a box action is 4 numbers (vx, vy, omega, kick), got {len(a)}: {a!r:.80}")
        for x in a:
            if not math.isfinite(x):  # NaN would clip to -1: full reverse
                raise ValueError(f"a box action's numbers must be finite, got {a!r:.80}")
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


def discrete_index(action: Any) -> int:
    """The move a discrete action names; ValueError unless it is one integer 0..9 (-1 must not play the last)."""
    a = np.asarray(action)
    v = a.reshape(-1)[0] if a.size == 1 else None
    whole = v is not None and (
        np.issubdtype(a.dtype, np.integer) or (np.issubdtype(a.dtype, np.floating) and math.isfinite(v) and v == int(v))
    )
    if not whole:
        raise ValueError(f"a discrete action is one integer 0..{len(DISCRETE) - 1}, got {action!r:.80}")
    i = int(v)
    if not 0 <= i < len(DISCRETE):
        raise ValueError(f"a discrete action is one of 0..{len(DISCRETE) - 1}, got {i}")
    return i


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
class MLPPolicy:
    """A multilayer perceptron: h = tanh(W_i h + b_i) through every layer, the last one included (so
    its output, 4 numbers, is a Box action in [-1, 1]; 10 numbers: scores of the discrete moves).
    float32 throughout, as its ONNX export computes (`save_policy` writes it without torch)."""

    def __init__(self, weights: Sequence[np.ndarray], biases: Sequence[np.ndarray]):
        self.weights = [np.asarray(w, dtype=np.float32) for w in weights]
        self.biases = [np.asarray(b, dtype=np.float32) for b in biases]
        if not self.weights or len(self.weights) != len(self.biases):
            raise ValueError("an MLPPolicy needs one bias per weight matrix, at least one layer")
        for i, (w, b) in enumerate(zip(self.weights, self.biases)):
            if w.ndim != 2 or b.shape != (w.shape[0],):
                raise ValueError(f"layer {i}: weights {w.shape} and bias {b.shape} do not fit (out x in, out)")
            if i and w.shape[1] != self.weights[i - 1].shape[0]:
                raise ValueError(
                    f"layer {i} takes {w.shape[1]} numbers, layer {i - 1} gives {self.weights[i - 1].shape[0]}"
                )

    @property
    def obs_size(self) -> int:
        return self.weights[0].shape[1]

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        h = np.asarray(obs, dtype=np.float32)
        for w, b in zip(self.weights, self.biases):
            h = np.tanh(w @ h + b)
        return h


class LinearPolicy(MLPPolicy):
    """action = tanh(W obs + b): a Box action from a flat observation (an `MLPPolicy` of one layer)."""

    def __init__(self, weights: np.ndarray, bias: np.ndarray):
        super().__init__([weights], [bias])


class RecordedActions:
    """Plays recorded actions in order, one per call (replays an episode; zeros once they run out)."""

    def __init__(self, actions: Sequence[Any]):
        self.actions = [np.asarray(a) for a in actions]
        self.i = 0

    def __call__(self, obs: np.ndarray) -> Any:
        a = self.actions[self.i] if self.i < len(self.actions) else np.zeros_like(self.actions[0])
        self.i += 1
        return a
