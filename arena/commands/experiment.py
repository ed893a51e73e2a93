"""`arena experiment`: questions a team asks of its strategy; `tune` searches its parameters
(arena/commands/_tune.py, docs/strategies.md "Tuning")."""

from __future__ import annotations

import argparse

from arena.commands._common import add_command
from arena.commands._tune import add_tune_parser, run_tune

EXAMPLES = """examples:
  arena experiment tune --strategy AD --opponents AS,BS --params kick_speed,keeper_gain --out runs/tune-ad
(docs/strategies.md, "Tuning")"""

CATCH_SIGTERM = True
STOPS_PROCESSES = True


def add_parser(sub) -> None:
    ex = add_command(sub, "experiment", "questions a team asks of its strategy: tune its parameters", EXAMPLES)
    what = ex.add_subparsers(dest="experiment", required=True, metavar="{tune}")
    add_tune_parser(what)


def run(args: argparse.Namespace) -> int:
    return run_tune(args)
