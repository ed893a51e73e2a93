"""Strategies by name: the built-ins and every ``soccer_arena.strategies`` entry point."""

from __future__ import annotations

from functools import cache
from importlib.metadata import entry_points

from arena.runtime.config import ConfigError
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
def all_strategies() -> dict[str, Strategy]:
    """Canonical name -> Strategy. Plugins cannot shadow a built-in name."""
    found: dict[str, Strategy] = {}
    for s in _builtin():
        found[s.name] = s
    for ep in sorted(entry_points(group=GROUP), key=lambda e: e.name):
        obj = ep.load()
        strategy = obj() if callable(obj) and not isinstance(obj, Strategy) else obj
        if not isinstance(strategy, Strategy):
            raise ConfigError(f"entry point {ep.name!r} in {GROUP} is not an arena Strategy")
        if strategy.name in found:
            continue
        found[strategy.name] = strategy
    return found


def resolve_name(name: str) -> str:
    """Canonical name for a name or alias (case-insensitive); ConfigError if unknown."""
    table = all_strategies()
    wanted = name.strip().lower()
    for s in table.values():
        if wanted == s.name.lower() or wanted in (a.lower() for a in s.aliases):
            return s.name
    names = ", ".join(f"{s.name} ({'/'.join(s.aliases)})" if s.aliases else s.name for s in table.values())
    raise ConfigError(f"unknown strategy {name!r}; known: {names}")


def get(name: str) -> Strategy:
    return all_strategies()[resolve_name(name)]
