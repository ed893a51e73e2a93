"""`arena strategies`: the built-in and plugin strategies, with their conformance status."""

from __future__ import annotations

import argparse
import json

from arena.commands._common import add_command

EXAMPLES = """examples:
  arena strategies                 # every strategy, built-in or plugin, and whether it passes the conformance suite
  arena strategies AD chase        # only these (a plugin by its name too)
  arena strategies --recheck       # run the suite even where the source has not changed since the last run
  arena strategies --no-check --json
  arena strategies --params AD     # AD's tunable parameters: name, type, default, range, unit, meaning
  arena strategies --params AD --json

A verdict is kept per strategy with the SHA-256 of its package's source and of the arena code the
suite runs, in $XDG_CACHE_HOME/soccer-arena (else ~/.cache/soccer-arena): the suite runs again only
for what changed, and the table marks a kept verdict "(kept)"."""


def add_parser(sub) -> None:
    st = add_command(
        sub,
        "strategies",
        "list the strategies: built-ins and installed plugins, with their conformance status",
        EXAMPLES,
    )
    st.add_argument("names", nargs="*", metavar="NAME", help="only these strategies (names or aliases)")
    st.add_argument(
        "--params",
        metavar="NAME",
        help="list this strategy's parameters (set them with arena match --param a.NAME=V or [params.a] in a file)",
    )
    check = st.add_mutually_exclusive_group()
    check.add_argument("--no-check", action="store_true", help="skip the conformance suite (~1.5 s per strategy)")
    check.add_argument(
        "--recheck", action="store_true", help="run the suite even for a strategy whose verdict is kept (unchanged)"
    )
    st.add_argument("--json", action="store_true", help="print one JSON object")


def run(args: argparse.Namespace) -> int:
    from arena.strategies import registry

    if args.params is not None:
        return show_params(registry.get(args.params), args.json)
    wanted = {registry.resolve_name(n) for n in args.names}
    rows = registry.describe(check=not args.no_check, only=wanted or None, recheck=args.recheck)
    if args.json:
        print(json.dumps({"strategies": rows}, indent=2))
        return 0
    from rich.markup import escape
    from rich.table import Table

    from arena.review.console import console as make_console

    t = Table(title="strategies (arena match --home NAME --away ALIAS)")
    for col in ("name", "alias", "from", "conformance"):
        t.add_column(col)
    for r in rows:
        verdict = r["conformance"] + (" (kept)" if r["cached"] else "")
        t.add_row(r["name"], "/".join(r["aliases"]) or "-", escape(r["source"]), escape(verdict))
    make_console().print(t)
    return 0 if not any(r["conformance"].startswith("fails") for r in rows) else 1


def show_params(strategy, as_json: bool) -> int:
    rows = [
        {
            "name": p.name,
            "type": p.type,
            "default": p.default,
            "low": p.low,
            "high": p.high,
            "choices": list(p.choices),
            "unit": p.unit,
            "meaning": p.meaning,
        }
        for p in strategy.params
    ]
    if as_json:
        print(json.dumps({"strategy": strategy.name, "params": rows}, indent=2))
        return 0
    from rich.markup import escape
    from rich.table import Table

    from arena.review.console import console as make_console

    if not rows:
        print(f"{strategy.name} declares no parameters")
        return 0
    title = f"{strategy.name}'s parameters (arena match --param a.NAME=VALUE; [params.a] in a match file)"
    t = Table(title=escape(title))
    for col in ("name", "type", "default", "range", "unit", "meaning"):
        t.add_column(col)
    for r in rows:
        span = "|".join(r["choices"]) if r["choices"] else "" if r["low"] is None else f"{r['low']:g}..{r['high']:g}"
        t.add_row(r["name"], r["type"], str(r["default"]), span, r["unit"], escape(r["meaning"]))
    make_console().print(t)
    return 0
