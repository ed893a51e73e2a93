"""Reading a scenario file: the built-in one, or a user's completed by it; every bad value is a `ScenarioError` with a one-line reason."""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import msgspec

from arena.experiments.navbench.checks import _check_timing, _merge, _on_field, _override, _robot, _unique
from arena.experiments.navbench.spec import (
    BUILTIN,
    BenchFile,
    BenchSpec,
    LocalMinimum,
    Scenario,
    ScenarioError,
    Scheme,
)
from arena.navigation import NAVIGATORS, PARAMS
from arena.sim.drive import Drive


def builtin_text() -> str:
    return resources.files("arena.experiments.navbench").joinpath(BUILTIN).read_text(encoding="utf-8")


def load(path: str | Path | None = None) -> BenchSpec:
    """The benchmark definitions: the built-in file, or ``path`` completed by it.

    A user file's [defaults] keys override the built-in [defaults] one by one;
    its [[scheme]] tables, if it has any, replace the built-in schemes. Its
    [[scenario]] and [[local_minimum]] tables are the ones that run. Raises
    ScenarioError with a one-line reason.
    """
    builtin = _parse(builtin_text(), f"built-in {BUILTIN}")
    if path is None:
        return _resolve(builtin, f"built-in {BUILTIN}")
    name = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"--scenarios {name}: no such file") from None
    except IsADirectoryError:
        raise ScenarioError(f"--scenarios {name}: is a directory") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"--scenarios {name}: cannot read: {exc}") from None
    user = _parse(text, name)
    defaults = user.get("defaults", {})
    if not isinstance(defaults, dict):
        raise ScenarioError(f"{name}: [defaults] must be a table")
    user["defaults"] = _merge(builtin.get("defaults", {}), defaults)
    if "scheme" not in user:
        user["scheme"] = builtin.get("scheme", [])
    if not user.get("scenario") and not user.get("local_minimum"):
        raise ScenarioError(f"{name}: no [[scenario]] or [[local_minimum]] table")
    return _resolve(user, name)


def _parse(text: str, name: str) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{name}: not valid TOML: {exc}") from None


def _resolve(data: dict[str, Any], name: str) -> BenchSpec:  # noqa: C901, PLR0912 - one branch per scenario key
    data = dict(data)
    defaults = data.pop("defaults", {})
    if not isinstance(defaults, dict):
        raise ScenarioError(f"{name}: [defaults] must be a table")
    scenarios = data.get("scenario", [])
    if isinstance(scenarios, list):
        data["scenario"] = [_merge(defaults, s) if isinstance(s, dict) else s for s in scenarios]
    try:
        spec = msgspec.convert(data, BenchFile)
    except msgspec.ValidationError as exc:
        raise ScenarioError(f"{name}: {exc}") from None

    schemes: dict[str, Scheme] = {}
    for s in spec.scheme:
        if s.name in schemes:
            raise ScenarioError(f"{name}: scheme {s.name!r} is defined twice")
        if s.method not in NAVIGATORS:
            raise ScenarioError(
                f"{name}: scheme {s.name!r}: unknown method {s.method!r} (known: {', '.join(NAVIGATORS)})"
            )
        params = _override(PARAMS[s.method](), s.params, f"{name}: scheme {s.name!r} params")
        schemes[s.name] = Scheme(s.name, s.method, s.label or s.name, params)

    seen: set[str] = set()
    scenarios_out = []
    for sc in spec.scenario:
        where = f"{name}: scenario {sc.name!r}"
        _unique(sc.name, seen, where)
        robot = _robot(sc.robot, sc.robot_params, where)
        _check_timing(sc.dt, sc.substeps, sc.time_limit, sc.goal_tolerance, where)
        drive = Drive(robot)
        if (sc.controller == "omni") != drive.holonomic:
            raise ScenarioError(f"{where}: controller {sc.controller!r} does not fit robot model {robot.model!r}")
        if not 1 <= len(sc.obstacles) <= 6:
            raise ScenarioError(f"{where}: needs 1 to 6 obstacles, got {len(sc.obstacles)}")
        for p in (sc.start, sc.target, *(o.start for o in sc.obstacles)):
            _on_field(p, where)
        for o in sc.obstacles:
            if o.pursue_speed < 0 or o.stop_distance < 0:
                raise ScenarioError(f"{where}: pursue_speed and stop_distance must be >= 0")
            if o.pursue_speed > 0 and o.velocity != (0.0, 0.0):
                raise ScenarioError(f"{where}: an obstacle has both velocity and pursue_speed; choose one")
        if sc.noise.obstacle_start_sigma < 0 or sc.noise.obstacle_speed_sigma < 0:
            raise ScenarioError(f"{where}: noise sigmas must be >= 0")
        names = sc.schemes if sc.schemes is not None else list(schemes)
        missing = [n for n in [*names, *sc.reference] if n not in schemes]
        if missing:
            raise ScenarioError(f"{where}: unknown scheme {missing[0]!r} (defined: {', '.join(schemes) or 'none'})")
        if not names:
            raise ScenarioError(f"{where}: no schemes to run")
        scenarios_out.append(Scenario(sc, robot, tuple(schemes[n] for n in names)))

    minima = []
    for lm in spec.local_minimum:
        where = f"{name}: local_minimum {lm.name!r}"
        _unique(lm.name, seen, where)
        robot = _robot(lm.robot, lm.robot_params, where)
        _check_timing(lm.dt, lm.substeps, lm.time_limit, lm.goal_tolerance, where)
        if Drive(robot).holonomic:
            raise ScenarioError(f"{where}: robot {lm.robot!r} is not a differential drive (model {robot.model!r})")
        if not 1 <= len(lm.obstacles) <= 6:
            raise ScenarioError(f"{where}: needs 1 to 6 obstacles, got {len(lm.obstacles)}")
        for p in (lm.start, lm.goal, *lm.obstacles):
            _on_field(p, where)
        methods = []
        for m, over in lm.methods.items():
            if m not in NAVIGATORS:
                raise ScenarioError(f"{where}: unknown method {m!r} (known: {', '.join(NAVIGATORS)})")
            methods.append((m, _override(PARAMS[m](), over, f"{where}: methods.{m}")))
        if not methods:
            raise ScenarioError(f"{where}: no methods")
        minima.append(LocalMinimum(lm, robot, tuple(methods)))
    return BenchSpec(name, tuple(scenarios_out), tuple(minima))
