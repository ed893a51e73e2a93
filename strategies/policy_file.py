"""Policy files: what `policy:PATH` plays, written by `save_policy`, read by `load_policy`.

Three forms, told apart by their content (never by the file name), none of which runs code when read:

* an ONNX model (the deployable form): one input, the flat observation (float32, `[1, D]` or `[D]`),
  and per robot an output `action_<n>` (or one output `action` shared by every robot it plays): a Box
  action (float, 4 numbers) or a discrete one (an integer index, or 10 scores of which the largest
  wins). Its `metadata_props` say how it plays (`META`). onnxruntime runs it, here and on a robot's
  own computer (schemas/README.md says how, in C++);
* recorded actions (`RecordedActions`, what `SoccerParallelEnv.save_actions` writes): JSON, an
  episode's actions per robot, played in order;
* a pickle of a `PolicyFile` (any Python callable): loading it runs whatever code it carries, so it
  loads only with an explicit opt-in (`--allow-pickle`, or ARENA_ALLOW_PICKLE=1 in the environment).

Every file is checked at load: its shapes against the match's observation, `frame_skip >= 1`, the
base strategy, and one trial decision on the observation a robot has before anything arrives, so a
bad file is one line (ConfigError) in the process that names it, before any robot starts.
"""

from __future__ import annotations

import json
import math
import os
import pickle
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from arena.config import ConfigError, MatchConfig
from arena.strategies.base import RobotContext, Strategy, TeamContext
from arena.strategies.learned import (
    DISCRETE,
    PREFIX,
    LearnerBrain,
    LinearPolicy,
    MLPPolicy,
    RecordedActions,
    View,
    observe,
)

PICKLE_ENV = "ARENA_ALLOW_PICKLE"  # "1": pickle policy files load (they run the code they hold)
MAX_BYTES = 256 * 2**20  # a policy file larger than this is refused unread
RECORDED = "arena-recorded-actions"  # the JSON form's `format`
# The ONNX model's metadata_props: how the file plays.
META = {
    "arena.base": "the strategy of the base station and of every robot the file does not play",
    "arena.robots": "the robot numbers the file plays, comma-separated (e.g. 1,2)",
    "arena.frame_skip": "control ticks per decision (>= 1); the action is held in between",
    "arena.actions": "box (4 numbers in [-1, 1]: vx, vy, omega, kick) or discrete (an index into 10 moves)",
    "arena.team_size": "the team size the observation is shaped for (its robot slots); 0: the match's",
    "arena.obs_size": "the observation's length, D",
}


def pickle_allowed() -> bool:
    return os.environ.get(PICKLE_ENV, "") == "1"


def allow_pickle() -> None:
    """The `--allow-pickle` flag: this process and every process it starts load pickle policy files."""
    os.environ[PICKLE_ENV] = "1"


@dataclass
class PolicyFile:
    """What a policy file holds: a policy (obs -> action) per robot number, and how it plays."""

    base: str  # the strategy of the team brain and of every robot without a policy
    policies: dict[int, Callable[[np.ndarray], Any]]
    frame_skip: int = 1
    discrete: bool = False
    robots: int = 0  # the team size it was trained with: its observations have that many robot slots (0: any)


# ------------------------------------------------------------------- writing
def save_policy(
    path: str | Path,
    policies: dict[int, Any],
    base: str,
    frame_skip: int = 1,
    discrete: bool = False,
    robots: int = 0,
    obs_size: int | None = None,
) -> Path:
    """Write an ONNX policy file: `policies` maps robot numbers to a `LinearPolicy` or `MLPPolicy`
    (exported with onnx's own helpers, no torch), an `onnx.ModelProto` (e.g. from `torch.onnx.export`),
    or the path of an .onnx file; each maps the flat observation to an action.

    `robots`: the team size it was trained with, so that a match of another size still gives it
    observations of the size it knows (the nearest robots fill the slots). `obs_size`: the
    observation's length, when no policy's weights say it. A path ending in .pkl writes the pickle
    form instead (any picklable callable; it loads only with --allow-pickle)."""
    p = Path(path)
    if frame_skip < 1:
        raise ValueError(f"frame_skip must be at least 1, got {frame_skip}")
    if p.suffix == ".pkl":
        p.write_bytes(pickle.dumps(PolicyFile(base, dict(policies), frame_skip, discrete, robots)))
        return p
    from arena.strategies.policy_onnx import team_model

    meta = {
        "arena.base": base,
        "arena.robots": ",".join(str(n) for n in sorted(policies)),
        "arena.frame_skip": str(frame_skip),
        "arena.actions": "discrete" if discrete else "box",
        "arena.team_size": str(robots),
    }
    p.write_bytes(team_model(dict(policies), meta, obs_size))
    return p


def save_recorded(
    path: str | Path, actions: dict[int, list[Any]], base: str, frame_skip: int, discrete: bool, robots: int
) -> Path:
    """Write recorded actions (JSON): robot number -> the actions it plays in order."""
    doc = {
        "format": RECORDED,
        "base": base,
        "frame_skip": frame_skip,
        "actions": "discrete" if discrete else "box",
        "team_size": robots,
        "robots": {str(n): [np.asarray(a).tolist() for a in acts] for n, acts in actions.items()},
    }
    p = Path(path)
    p.write_text(json.dumps(doc))
    return p


# ------------------------------------------------------------------- reading
def load_policy(path: str | Path, allow_pickle: bool | None = None) -> PolicyFile:
    """Read a policy file (ONNX, recorded actions, or with `allow_pickle` a pickle); ConfigError (one line)
    if it cannot be. `allow_pickle` None: as ARENA_ALLOW_PICKLE says (the --allow-pickle flag sets it)."""
    data = _read(path)
    if data.lstrip()[:1] == b"{":
        return _recorded(path, data)
    allowed = pickle_allowed() if allow_pickle is None else allow_pickle
    if data[:1] == b"\x80":  # every pickle protocol from 2 on
        if not allowed:
            raise ConfigError(
                f"policy file {path} is a pickle, and loading a pickle runs any code it holds: refused "
                "(save it as ONNX with arena.learn.save_policy, or trust it with --allow-pickle)"
            )
        return _pickled(path, data)
    from arena.strategies.policy_onnx import load_onnx

    try:
        return load_onnx(path, data)
    except ConfigError:
        if not allowed or not data[:1].isascii():  # a protocol 0 or 1 pickle, trusted: the last try
            raise
    return _pickled(path, data)


def _read(path: str | Path) -> bytes:
    p = Path(path)
    try:
        if not p.is_file() and p.exists() and not p.is_dir():
            raise ConfigError(f"policy file {path} is not a regular file")
        size = p.stat().st_size
        if size > MAX_BYTES:
            raise ConfigError(f"policy file {path} is {size} bytes, more than the {MAX_BYTES} a policy file may be")
        return p.read_bytes()
    except FileNotFoundError:
        raise ConfigError(f"policy file {path} not found") from None
    except IsADirectoryError:
        raise ConfigError(f"policy file {path} is a directory: give the file save_policy wrote") from None
    except OSError as exc:
        raise ConfigError(f"policy file {path} cannot be read: {exc.strerror or exc}") from None


def _pickled(path, data: bytes) -> PolicyFile:
    try:
        pf = pickle.loads(data)
    except Exception as exc:  # anything a file that is not a pickle of ours makes pickle raise
        raise ConfigError(f"policy file {path} cannot be read: {type(exc).__name__}: {exc}") from None
    if not isinstance(pf, PolicyFile):
        raise ConfigError(f"policy file {path} is not an arena policy (write it with arena.learn.save_policy)")
    return pf


def _recorded(path, data: bytes) -> PolicyFile:
    def bad(why: str) -> ConfigError:
        return ConfigError(f"policy file {path} is not an arena recorded-actions file: {why}")

    try:
        doc = json.loads(data)
    except (ValueError, RecursionError) as exc:
        raise bad(f"not JSON ({str(exc).splitlines()[0][:80]})") from None
    if not isinstance(doc, dict) or doc.get("format") != RECORDED:
        raise bad(f'no "format": "{RECORDED}"')
    discrete = _form(path, doc.get("actions"))
    fs, size = doc.get("frame_skip"), doc.get("team_size", 0)
    base = doc.get("base")
    if not isinstance(fs, int) or isinstance(fs, bool) or fs < 1:
        raise ConfigError(f"policy file {path}: frame_skip must be an integer of at least 1, got {fs!r}")
    if not isinstance(size, int) or isinstance(size, bool) or not 0 <= size <= 11:
        raise bad(f"team_size must be 0..11, got {size!r}")
    if not isinstance(base, str):
        raise bad("no base strategy")
    robots = doc.get("robots")
    if not isinstance(robots, dict) or not robots:
        raise bad('"robots" must map robot numbers to lists of actions')
    policies: dict[int, Callable] = {}
    for n, acts in robots.items():
        if not n.isdigit() or not isinstance(acts, list) or not acts:
            raise bad(f"robot {n!r}: a robot number and a non-empty list of actions")
        for a in acts:
            if not _valid_action(a, discrete):
                raise bad(f"robot {n}: {str(a)[:40]} is not a {'discrete' if discrete else 'box'} action")
        policies[int(n)] = RecordedActions(acts)
    return PolicyFile(base, policies, fs, discrete, size)


def _form(path, value) -> bool:
    if value not in ("box", "discrete"):
        raise ConfigError(f"policy file {path}: actions must be box or discrete, got {value!r}")
    return value == "discrete"


def _valid_action(a: Any, discrete: bool) -> bool:
    if discrete:
        return isinstance(a, int) and not isinstance(a, bool) and 0 <= a < len(DISCRETE)
    return (
        isinstance(a, list)
        and len(a) == 4
        and all(isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x) for x in a)
    )


def check(path, pf: PolicyFile, view: View) -> None:
    """One trial decision per policy on the observation a robot has before anything arrives: the
    action's form and range, so that a bad policy is refused here, not at a robot's tick 0."""
    obs = observe(None, None, view)
    for n, policy in pf.policies.items():
        if isinstance(policy, RecordedActions):
            continue
        try:
            action = policy(obs.copy())
        except Exception as exc:  # a pickled callable or a model: whatever it raises on a valid observation
            msg = (str(exc).splitlines() or [""])[0][:160]
            raise ConfigError(
                f"policy file {path}: robot {n}'s policy fails on a {view.size}-number observation: "
                f"{type(exc).__name__}: {msg}"
            ) from None
        problem = action_problem(action, pf.discrete)
        if problem:
            raise ConfigError(f"policy file {path}: robot {n}'s policy {problem}")


def action_problem(action: Any, discrete: bool) -> str:
    """What is wrong with an action ("" when nothing): its shape, or a value that is not finite or out of range."""
    if discrete:
        a = np.asarray(action)
        if a.size != 1 or not np.issubdtype(a.dtype, np.integer):
            return f"gives {_shown(action)}, not one integer (a discrete action, 0..{len(DISCRETE) - 1})"
        if not 0 <= int(a.reshape(-1)[0]) < len(DISCRETE):
            return f"gives {int(a.reshape(-1)[0])}, not a discrete action 0..{len(DISCRETE) - 1}"
        return ""
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError):
        return f"gives {_shown(action)}, not 4 numbers (vx, vy, omega, kick)"
    if a.shape != (4,):
        return f"gives shape {a.shape}, not 4 numbers (vx, vy, omega, kick)"
    if not np.isfinite(a).all():
        return f"gives a value that is not finite: {a.tolist()}"
    return ""


def _shown(x: Any) -> str:
    return repr(x)[:60]


# ------------------------------------------------------------------ playing
@cache
def policy_strategy(name: str) -> Strategy:
    """The strategy `policy:PATH`: the file's policies play their robots, its `base` the rest."""
    from arena.strategies import registry

    path = name[len(PREFIX) :]
    pf = load_policy(path)
    if pf.base.startswith(PREFIX):
        raise ConfigError(f"policy file {path}: its base strategy is itself a policy file ({pf.base})")
    base = registry.get(pf.base)
    if not 0 <= pf.robots <= 11:
        raise ConfigError(f"policy file {path}: team size {pf.robots} is not 0..11")
    check(path, pf, View.of(MatchConfig(robots=pf.robots or 3), "a", pf.robots))

    def make_robot(ctx: RobotContext):
        if ctx.n not in pf.policies:
            return base.make_robot(ctx)
        view = View.of(ctx.cfg, ctx.team, pf.robots)
        policy = load_policy(path).policies[ctx.n]  # a fresh copy per robot: policies may keep state
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


__all__ = [
    "META",
    "PICKLE_ENV",
    "LinearPolicy",
    "MLPPolicy",
    "PolicyFile",
    "allow_pickle",
    "load_policy",
    "policy_strategy",
    "save_policy",
    "save_recorded",
]
