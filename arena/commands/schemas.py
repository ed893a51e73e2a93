"""`arena schemas`: check or rewrite schemas/README.md from schemas/messages.py."""

from __future__ import annotations

import argparse

from arena.commands._common import add_command

EXAMPLES = """examples:
  arena schemas --check            # is schemas/README.md up to date with schemas/messages.py?
  arena schemas --write"""


def add_parser(sub) -> None:
    s = add_command(
        sub, "schemas", "the wire contract: check or rewrite schemas/README.md from schemas/messages.py", EXAMPLES
    )
    g = s.add_mutually_exclusive_group()
    g.add_argument("--check", action="store_true", help="exit 1 if schemas/README.md is stale")
    g.add_argument("--write", action="store_true", help="rewrite schemas/README.md")


def run(args: argparse.Namespace) -> int:
    from arena.schemas import contract

    return contract.main(check=args.check, write=args.write)
