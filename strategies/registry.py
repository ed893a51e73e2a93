"""Strategies by name: the built-ins and every ``soccer_arena.strategies`` entry point."""

from __future__ import annotations

from functools import cache
from pathlib import Path

from arena.config import ConfigError, MatchConfig, ParamValue
from arena.strategies.base import POLICY_PREFIX, Strategy, check_values

GROUP = "soccer_arena.strategies"


def _builtin() -> list[Strategy]:
    """The paper's four strategies (iris.py) and chase-and-shoot (simple.py) as `chase`."""
    from arena.strategies import iris, simple

    paper = {s.name for s in iris.STRATEGIES}
    chase = [
        Strategy(name="chase", make_team=s.make_team, make_robot=s.make_robot, description="chase-and-shoot baseline")
        for s in simple.STRATEGIES[:1]
    ]
    return iris.STRATEGIES + [s for s in simple.STRATEGIES if s.name not in paper] + chase


@cache
def builtin_strategies() -> dict[str, Strategy]:
    """Canonical name -> Strategy, the built-ins only."""
    return {s.name: s for s in _builtin()}


@cache
def all_strategies() -> dict[str, Strategy]:
    """Canonical name -> Strategy. Plugins cannot shadow a built-in name."""
    # Imported here: importlib.metadata costs ~30 ms of CPU, paid by every
    # process of every match if it were imported for a built-in name.
    from importlib.metadata import entry_points

    found = dict(builtin_strategies())
    for ep in sorted(entry_points(group=GROUP), key=lambda e: e.name):
        obj = ep.load()
        strategy = obj() if callable(obj) and not isinstance(obj, Strategy) else obj
        if not isinstance(strategy, Strategy):
            raise ConfigError(f"entry point {ep.name!r} in {GROUP} is not an arena Strategy")
        if strategy.name in found:
            continue
        found[strategy.name] = strategy
    return found


def describe(check: bool = True, only: set[str] | None = None, recheck: bool = False) -> list[dict]:
    """One row per strategy: name, aliases, where it comes from, conformance (`arena strategies`).

    `source` is the module of a built-in, or the plugin's distribution and
    entry point; `conformance` is "passes", "fails: <the first failed check>"
    or "not checked"; `cached` whether that verdict was kept from an earlier run of
    the suite on the same source (strategies/checked.py; `recheck` runs it anyway).
    """
    from importlib.metadata import entry_points

    plugins = {}
    for ep in entry_points(group=GROUP):
        dist = ep.dist.name if ep.dist is not None else "?"
        plugins[ep.name] = f"plugin {dist} ({ep.value})"
    rows = []
    for name, s in all_strategies().items():
        if only is not None and name not in only:
            continue
        if name in builtin_strategies():
            source = f"built-in {s.make_team.__module__}"
        else:
            source = next((v for k, v in plugins.items() if k == name or k in s.aliases), "plugin")
        status, cached = "not checked", False
        if check:
            from arena.strategies import checked

            status, cached = checked.verdict(s, recheck)
        rows.append(
            {"name": name, "aliases": list(s.aliases), "source": source, "conformance": status, "cached": cached}
        )
    return rows


def _find(table: dict[str, Strategy], wanted: str) -> str | None:
    for s in table.values():
        if wanted == s.name.lower() or wanted in (a.lower() for a in s.aliases):
            return s.name
    return None


def resolve_name(name: str) -> str:
    """Canonical name for a name or alias (case-insensitive); ConfigError if unknown.

    Built-ins come first, as in `all_strategies`, so the entry points are read
    only for a name that is not built in.
    """
    if name.startswith(POLICY_PREFIX):  # a policy file: its absolute path, as every process opens it
        from arena.strategies import policy_file  # the policy-file modules: imported for a policy file only

        if not name[len(POLICY_PREFIX) :].strip():  # Path("") is the working directory
            raise ConfigError(f"{name!r} names no file: policy:PATH, a file written by arena.learn.save_policy")
        return policy_file.policy_strategy(POLICY_PREFIX + str(Path(name[len(POLICY_PREFIX) :]).resolve())).name
    wanted = name.strip().lower()
    found = _find(builtin_strategies(), wanted) or _find(all_strategies(), wanted)
    if found is not None:
        return found
    table = all_strategies()
    names = ", ".join(f"{s.name} ({'/'.join(s.aliases)})" if s.aliases else s.name for s in table.values())
    raise ConfigError(
        f"unknown strategy {name!r}; known: {names} (a plugin is known once its package is installed:"
        " entry point soccer_arena.strategies, docs/strategies.md)"
    )


def get(name: str) -> Strategy:
    if name.startswith(POLICY_PREFIX):
        from arena.strategies import policy_file

        return policy_file.policy_strategy(name)
    canonical = resolve_name(name)
    return builtin_strategies().get(canonical) or all_strategies()[canonical]


def check_params(cfg: MatchConfig) -> MatchConfig:
    """`cfg` with its `params` checked against each team's strategy (`Strategy.params`): ConfigError, one
    line naming the strategy's parameters, for an unknown name, a wrong type or a value out of range.
    Returns `cfg` with each value as its parameter's type (an int given for a float is that float)."""
    if not cfg.params:
        return cfg
    out = {}
    for team, given in sorted(cfg.params.items()):
        strategy = get(cfg.strategy_of(team))
        try:
            out[team] = check_values(strategy.name, strategy.params, given)
        except ConfigError as exc:
            raise ConfigError(f"params.{team}: {exc}") from None
    return cfg if out == cfg.params and _same_types(out, cfg.params) else cfg.replace(params=out)


def _same_types(a: dict, b: dict) -> bool:
    return all(type(v) is type(b[t][k]) for t, vs in a.items() for k, v in vs.items())


def parse_param(text: str, teams: tuple[str, ...] = ("a", "b")) -> tuple[str, str, ParamValue]:
    """`a.kick_speed=7.0` (`--param`) as (team, name, value); the value a TOML scalar (7, 7.0, true, "f-sfm",
    or a bare word as a string). `teams`: the prefixes accepted (a tournament takes strategy names)."""
    import tomllib

    head, sep, raw = text.partition("=")
    team, dot, name = head.strip().partition(".")
    if not sep or not dot or not name or not raw.strip():
        raise ConfigError(f"--param {text!r}: use TEAM.NAME=VALUE, e.g. a.kick_speed=7.0")
    if teams and team not in teams:
        raise ConfigError(f"--param {text!r}: {team!r} is not one of {', '.join(teams)}")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    if not isinstance(value, bool | int | float | str):
        raise ConfigError(f"--param {text!r}: the value must be a number, true/false or a word")
    return team, name.strip(), value
