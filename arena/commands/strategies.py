"""`arena strategies`: the built-in and plugin strategies, with their conformance status."""

from __future__ import annotations

import argparse
import json

from arena.commands._common import add_command

EXAMPLES = """examples:
  arena strategies                 # every strategy, built-in or plugin, and whether it passes the conformance suite
  arena strategies AD chase        # only these (a plugin by its name too)
  arena strategies --no-check --json"""


def add_parser(sub) -> None:
    st = add_command(
        sub,
        "strategies",
        "list the strategies: built-ins and installed plugins, with their conformance status",
        EXAMPLES,
    )
    st.add_argument("names", nargs="*", metavar="NAME", help="only these strategies (names or aliases)")
    st.add_argument("--no-check", action="store_true", help="skip the conformance suite (~1.5 s per strategy)")
    st.add_argument("--json", action="store_true", help="print one JSON object")


def run(args: argparse.Namespace) -> int:
    from arena.strategies import registry

    wanted = {registry.resolve_name(n) for n in args.names}
    rows = [r for r in registry.describe(check=not args.no_check, only=wanted or None)]
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
        t.add_row(r["name"], "/".join(r["aliases"]) or "-", escape(r["source"]), escape(r["conformance"]))
    make_console().print(t)
    return 0 if not any(r["conformance"].startswith("fails") for r in rows) else 1
