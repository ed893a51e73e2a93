"""A match configuration file (TOML): `arena match --config FILE.toml`, `arena config --print`.

The file holds the `MatchConfig` tree a user may want to change: the match
(seed, strategies, robots, half time), `[links]` (the preset and per-class
overrides), `[field]`, `[robot]`, `[ball]`, `[sensor]`, `[rules]` and
`[timing]`, and `[params.a]`/`[params.b]` (each team's strategy parameters;
which names, types and ranges a strategy takes is checked where the
strategies are known, `registry.check_params`). Every key is optional; a
missing one keeps its default. An unknown key, a wrong type or a value out of
range is a `ConfigError` that names the key
(`field.lenght`, `robot.mass`). `dump()` writes the defaults with each key's
unit and meaning taken from the comments in config/__init__.py, so the printed
file documents itself. Deployment matters (real time, --external, --record,
the RefBox bridge) stay command-line flags.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import re
from typing import Any

from arena.config import ConfigError, MatchConfig
from arena.runtime import userfile

TOP = ("seed", "home", "away", "robots", "half_time")
SECTIONS = ("field", "robot", "ball", "sensor", "rules", "timing")


def _comments(cls: type) -> dict[str, str]:
    """`name: type = value  # comment` lines of a dataclass's source: name -> comment."""
    try:
        source = inspect.getsource(cls)
    except (OSError, TypeError):
        return {}
    return dict(re.findall(r"^\s+(\w+): [^=\n]+=[^#\n]*#\s*(.+)$", source, flags=re.M))


MAX_FIELD = 100.0  # [m] any length of [field]; an MSL field is 22 x 14 m
# Numbers of those sections for which 0 means something (MatchConfig.validate checks their range).
ZERO_ALLOWED = frozenset({"perception_latency", "batch", "kick_max_speed", "lob_angle", "dribble_max_omega"})
MAX_ROBOT_SIZE = 2.0  # [m] an MSL robot is at most 0.52 m wide
# Upper bounds of the numbers a file may set, far beyond anything playable but short of what
# overflows the physics (1e308 kg, a 1e300 rad/s wheel): the unit's plausible limit, per key.
# A number without its own row is at most MAX_NUMBER; [field] lengths at most MAX_FIELD.
MAX_NUMBER = 1e6
MAX_WALL_S = 86_400.0  # [s] a wall-clock wait of a day
MAX_RULE_S = 3_600.0  # [s] a rule's time: one half at most
UPPER = {
    "robot": {"size": MAX_ROBOT_SIZE, "height": 5.0, "mass": 1000.0, "max_speed": 50.0, "max_accel": 100.0,
              "max_omega": 100.0, "max_alpha": 1000.0, "wheel_radius": 1.0, "wheel_base": MAX_ROBOT_SIZE,
              "max_wheel_speed": 10_000.0, "kick_max_speed": 50.0, "lob_angle": math.pi / 2,
              "dribble_max_omega": 100.0, "cmd_timeout": 60.0},
    "ball": {"radius": 1.0, "mass": 100.0, "rolling_decel": 100.0, "restitution": 1.0},
    "sensor": {"pose_sigma": 10.0, "heading_sigma": math.pi, "ball_range": 2 * MAX_FIELD,
               "robot_range": 2 * MAX_FIELD, "det_sigma": 10.0, "det_sigma_per_m": 1.0},
    "rules": {"kickoff_time": MAX_RULE_S, "setpiece_time": MAX_RULE_S, "take_time": MAX_RULE_S,
              "no_progress_s": MAX_RULE_S, "stuck_s": MAX_RULE_S, "setpiece_distance": MAX_FIELD,
              "drop_ball_distance": MAX_FIELD, "progress_radius": MAX_FIELD, "push_speed": 100.0,
              "dribble_limit": MAX_FIELD, "drop_ball_inset": MAX_FIELD, "spot_inset": MAX_FIELD,
              "corner_inset": MAX_FIELD, "yellow_fouls": 1000, "red_fouls": 1000, "stuck_radius": MAX_FIELD},
    "timing": {"substeps": 1000, "perception_latency": 1000, "batch": 1000, "startup_timeout": MAX_WALL_S,
               "wait_timeout": MAX_WALL_S, "lease": MAX_WALL_S, "summary_grace": MAX_WALL_S,
               "finish_grace": MAX_WALL_S},
}  # fmt: skip
MIN_DT = 1e-4  # [s] a 10 kHz control tick; finer would take days per simulated minute


def _known(section: str) -> dict[str, Any]:
    return {f.name: f for f in dataclasses.fields(getattr(MatchConfig(), section))}


def _check_keys(data: dict[str, Any], where: str) -> None:
    allowed_top = set(TOP) | set(SECTIONS) | {"links", "params"}
    for key in data:
        if key not in allowed_top:
            raise ConfigError(f"{where}: unknown key {key!r} (known: {', '.join(sorted(allowed_top))})")
    for section in SECTIONS:
        table = data.get(section, {})
        if not isinstance(table, dict):
            raise ConfigError(f"{where}: {section} must be a table ([{section}])")
        known = _known(section)
        for key in table:
            if key not in known:
                raise ConfigError(f"{where}: unknown key {section}.{key} (known: {', '.join(known)})")


def _check_values(cfg: MatchConfig, where: str) -> None:
    """Every number finite; sizes, masses, speeds and times positive (the engine cannot play a 0 m field)."""
    for section in SECTIONS:
        params = getattr(cfg, section)
        for f in dataclasses.fields(params):
            value = getattr(params, f.name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                continue
            if not math.isfinite(value) or value < 0:
                raise ConfigError(f"{where}: {section}.{f.name} must be a finite number >= 0, got {value}")
            if section in ("field", "ball", "timing", "robot") and value == 0 and f.name not in ZERO_ALLOWED:
                raise ConfigError(f"{where}: {section}.{f.name} must be > 0")
            if section == "field" and value > MAX_FIELD:  # every field entry is a length
                raise ConfigError(f"{where}: field.{f.name} must be at most {MAX_FIELD:g} m, got {value}")
            upper = UPPER.get(section, {}).get(f.name, MAX_NUMBER)
            if value > upper:
                unit = re.match(r"\[([^\]-]+)\]", _comments(type(params)).get(f.name, ""))
                unit_text = f" {unit.group(1)}" if unit else ""
                raise ConfigError(f"{where}: {section}.{f.name} must be at most {upper:g}{unit_text}, got {value:g}")
    if cfg.timing.dt < MIN_DT:
        raise ConfigError(f"{where}: timing.dt must be at least {MIN_DT:g} s, got {cfg.timing.dt:g}")
    fp = cfg.field
    if fp.goal_width >= fp.width or fp.penalty_area_width >= fp.width or fp.penalty_area_depth * 2 >= fp.length:
        raise ConfigError(f"{where}: field: the goal and the penalty areas must fit inside the field")


def to_dict(data: dict[str, Any], where: str) -> dict[str, Any]:
    """A parsed TOML document as `MatchConfig.from_dict` input, keys checked."""
    _check_keys(data, where)
    out = {k: data[k] for k in TOP if k in data}
    for section in SECTIONS:
        if section in data:
            out[section] = dict(data[section])
    links = data.get("links", {})
    if not isinstance(links, dict):
        raise ConfigError(f"{where}: links must be a table ([links])")
    if "preset" in links:
        out["link"] = links["preset"]
    overrides = {k: v for k, v in links.items() if k != "preset"}
    for cls, params in overrides.items():
        if not isinstance(params, dict):
            raise ConfigError(f"{where}: unknown key links.{cls} (known: preset, and one table per link class)")
    if overrides:
        out["link_overrides"] = overrides
    params = data.get("params", {})
    if not isinstance(params, dict) or not all(isinstance(v, dict) for v in params.values()):
        raise ConfigError(f"{where}: params must hold one table per team: [params.a] kick_speed = 7.0")
    if params:
        out["params"] = {team: dict(values) for team, values in params.items()}
    return out


def load(path: str, under: dict[str, Any] | None = None) -> MatchConfig:
    """Read and validate FILE.toml; ConfigError naming the file and the bad key. `under`: values of
    the top-level keys (`TOP`) that apply where the file has none (a command's own defaults)."""
    data = userfile.load_toml(path, "--config")  # regular, bounded, UTF-8, nesting bounded
    return from_data({**{k: v for k, v in (under or {}).items() if k in TOP}, **to_dict(data, path)}, path)


def from_data(raw: dict[str, Any], path: str) -> MatchConfig:
    """`MatchConfig.from_dict(raw)` with the file's checks (links, finite and positive numbers);
    ConfigError naming `path` and the bad key (an experiment builds each cell's configuration so)."""
    try:
        cfg = MatchConfig.from_dict(raw)
    except ConfigError as exc:
        text = str(exc)
        # msgspec says "... - at `$.field.length`": name the key as the file spells it
        m = re.search(r"(.*?) - at `\$\.(.+?)`", text)
        if m:
            key = m.group(2).replace("link_overrides", "links")
            raise ConfigError(f"{path}: {key}: {m.group(1).replace('invalid match configuration: ', '')}") from None
        raise ConfigError(f"{path}: {text}") from None
    from arena.runtime.links import resolve

    try:
        resolve(cfg.link, cfg.link_overrides)
    except ConfigError as exc:
        raise ConfigError(f"{path}: links: {exc}") from None
    _check_values(cfg, path)
    return cfg


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, int):
        return str(value)
    return '"' + str(value).replace("\\", "\\\\").replace('"', '\\"') + '"'


def dump(cfg: MatchConfig | None = None) -> str:
    """`cfg` (default: the defaults) as a commented TOML file that `load` reads back to the same values."""
    cfg = cfg or MatchConfig()
    top_notes = _comments(MatchConfig)
    lines = [
        "# soccer-arena match configuration: arena match --config FILE.toml",
        "# Every key is optional (a missing one keeps this default); flags given on the command line win.",
        "",
    ]
    for key in TOP:
        note = top_notes.get(key)
        lines.append(f"{key} = {_toml_value(getattr(cfg, key))}" + (f"  # {note}" if note else ""))
    lines += ["", "[links]", f"preset = {_toml_value(cfg.link)}  # ideal | lan | wifi | congested-wifi"]
    lines.append(
        "# per-class overrides, e.g. [links.wifi] latency_ms = 30 (arena match --link-param wifi.latency_ms=30)"
    )
    for cls, params in sorted(cfg.link_overrides.items()):
        lines += ["", f"[links.{cls}]"] + [f"{p} = {_toml_value(v)}" for p, v in sorted(params.items())]
    lines += [
        "",
        "# strategy parameters per team over the strategy's defaults (arena strategies --params NAME),",
        "# e.g. [params.a] kick_speed = 7.0 (arena match --param a.kick_speed=7.0)",
    ]
    for team, values in sorted(cfg.params.items()):
        lines += ["", f"[params.{team}]"] + [f"{p} = {_toml_value(v)}" for p, v in sorted(values.items())]
    for section in SECTIONS:
        params = getattr(cfg, section)
        notes = _comments(type(params))
        doc = (inspect.getdoc(type(params)) or "").splitlines()
        if doc and doc[0].startswith(type(params).__name__ + "("):
            doc = []  # dataclass's generated signature, not a description
        lines += [""] + ([f"# {doc[0]}"] if doc else []) + [f"[{section}]"]
        for f in dataclasses.fields(params):
            note = notes.get(f.name)
            lines.append(f"{f.name} = {_toml_value(getattr(params, f.name))}" + (f"  # {note}" if note else ""))
    return "\n".join(lines) + "\n"
