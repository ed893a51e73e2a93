"""Strategies by name: the built-ins and every ``soccer_arena.strategies`` entry point."""

from __future__ import annotations

from functools import cache
from pathlib import Path

from arena.runtime.config import ConfigError
from arena.strategies import learned, policy_file
from arena.strategies.base import Strategy

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
    if name.startswith(learned.PREFIX):  # a policy file: its absolute path, as every process opens it
        if not name[len(learned.PREFIX) :].strip():  # Path("") is the working directory
            raise ConfigError(f"{name!r} names no file: policy:PATH, a file written by arena.learn.save_policy")
        return policy_file.policy_strategy(learned.PREFIX + str(Path(name[len(learned.PREFIX) :]).resolve())).name
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
    if name.startswith(learned.PREFIX):
        return policy_file.policy_strategy(name)
    canonical = resolve_name(name)
    return builtin_strategies().get(canonical) or all_strategies()[canonical]
