"""`arena replay FILE.mcap --process PROC`: re-run processes against their recorded inputs."""

from __future__ import annotations

import argparse

from arena.commands._common import add_command

EXAMPLES = """examples:
  arena replay match.mcap --process robot/a/1          # re-run one process against its recorded inputs
  arena replay match.mcap --process basestation/b --json
  arena replay match.mcap --process all                # every process of the match"""


def add_parser(sub) -> None:
    y = add_command(sub, "replay", "re-run one process against its recorded inputs and compare its outputs", EXAMPLES)
    y.add_argument("file", help="an MCAP file written by arena match --record (lockstep)")
    y.add_argument(
        "--process",
        action="append",
        required=True,
        metavar="PROC",
        help="robot/a/1 (or a/1), basestation/b, engine, referee, or all (repeatable)",
    )
    y.add_argument("--json", action="store_true", help="print JSON instead of text")


def run(args: argparse.Namespace) -> int:
    from arena.review import replay

    return replay.main(args.file, args.process, as_json=args.json)
