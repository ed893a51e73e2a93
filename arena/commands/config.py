"""`arena config`: print the match configuration's defaults, or check a file."""

from __future__ import annotations

import argparse
import sys

from arena.commands._common import add_command

EXAMPLES = """examples:
  arena config --print > match.toml           # every key with its default, unit and meaning
  arena match --config match.toml --seed 3    # flags given on the command line win over the file
  arena config --check match.toml             # one line naming the bad key, or the whole file completed"""


def add_parser(sub) -> None:
    cf = add_command(
        sub,
        "config",
        "the match configuration file: print the defaults, or check a file (arena match --config)",
        EXAMPLES,
    )
    cg = cf.add_mutually_exclusive_group(required=True)
    cg.add_argument("--print", dest="print_defaults", action="store_true", help="write the defaults as TOML to stdout")
    cg.add_argument("--check", metavar="FILE.toml", help="validate FILE and print it completed with the defaults")


def run(args: argparse.Namespace) -> int:
    from arena.runtime import matchfile

    cfg = matchfile.load(args.check) if args.check else None
    sys.stdout.write(matchfile.dump(cfg))
    return 0
