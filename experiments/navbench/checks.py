"""Checks of one scenario entry: its robot preset, timing and positions, typed parameter overrides,
unique names, and merging a table over its defaults."""

from __future__ import annotations

import dataclasses
from typing import Any

from arena import config as runtime_config
from arena.config import RobotParams
from arena.experiments.navbench.spec import ScenarioError
from arena.sim.drive import Drive


def _robot(preset: str, overrides: dict[str, Any], where: str) -> RobotParams:
    rp = getattr(runtime_config, preset, None)
    if not isinstance(rp, RobotParams):
        known = [k for k, v in vars(runtime_config).items() if isinstance(v, RobotParams)]
        raise ScenarioError(f"{where}: unknown robot {preset!r} (presets in arena.config: {', '.join(known)})")
    rp = _override(rp, overrides, f"{where}: robot_params")
    if not (rp.size > 0 and rp.mass > 0 and rp.max_accel > 0 and rp.max_alpha > 0 and rp.max_wheel_speed > 0):
        raise ScenarioError(f"{where}: robot size, mass, max_accel, max_alpha and max_wheel_speed must be > 0")
    try:
        Drive(rp)
    except ValueError as exc:
        raise ScenarioError(f"{where}: {exc}") from None
    return rp


def _check_timing(dt: float, substeps: int, time_limit: float, tol: float, where: str) -> None:
    if not (dt > 0 and substeps >= 1 and time_limit > 0 and tol > 0):
        raise ScenarioError(f"{where}: dt, time_limit and goal_tolerance must be > 0 and substeps >= 1")
    if time_limit / dt > 1_000_000:
        raise ScenarioError(f"{where}: time_limit / dt is over a million iterations")


def _on_field(p: tuple[float, float], where: str) -> None:
    f = runtime_config.FieldParams()
    if abs(p[0]) > f.length / 2 or abs(p[1]) > f.width / 2:
        raise ScenarioError(f"{where}: position {list(p)} is off the {f.length:g} m x {f.width:g} m field")


def _override(obj: Any, overrides: dict[str, Any], where: str) -> Any:
    """``obj`` (a frozen params dataclass) with ``overrides`` applied; nested tables go into nested dataclasses."""
    fields = {f.name: f for f in dataclasses.fields(obj) if f.init}
    changes: dict[str, Any] = {}
    for key, value in overrides.items():
        if key not in fields:
            raise ScenarioError(f"{where}: unknown parameter {key!r} (known: {', '.join(fields)})")
        current = getattr(obj, key)
        if dataclasses.is_dataclass(current):
            if not isinstance(value, dict):
                raise ScenarioError(f"{where}.{key}: expected a table")
            changes[key] = _override(current, value, f"{where}.{key}")
        elif isinstance(current, bool) or isinstance(value, bool):
            if not (isinstance(current, bool) and isinstance(value, bool)):
                raise ScenarioError(f"{where}.{key}: expected {type(current).__name__}, got {value!r}")
            changes[key] = value
        elif isinstance(current, float) and isinstance(value, (int, float)):
            changes[key] = float(value)
        elif type(value) is not type(current):
            raise ScenarioError(f"{where}.{key}: expected {type(current).__name__}, got {value!r}")
        else:
            changes[key] = value
    try:
        return dataclasses.replace(obj, **changes)
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"{where}: {exc}") from None


def _merge(defaults: dict[str, Any], table: dict[str, Any]) -> dict[str, Any]:
    out = dict(defaults)
    for k, v in table.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _unique(name: str, seen: set[str], where: str) -> None:
    if name in seen:
        raise ScenarioError(f"{where}: the name is used twice")
    seen.add(name)
