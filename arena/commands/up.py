"""`arena up FILE`: the services of a compose file as local processes."""

from __future__ import annotations

import argparse
import sys

from arena.commands._common import add_command, emit_match, one_line, seconds

CATCH_SIGTERM = True
STOPS_PROCESSES = True

EXAMPLES = """The match is compose.yaml's: 2 x 300 s of basic-static vs advance-dynamic, seed 7, link wifi,
unless the environment says otherwise (the same variables docker compose expands):
  ARENA_HOME, ARENA_AWAY   strategies of team a and team b
  ARENA_HALF_TIME          simulated seconds per half (300)
  ARENA_SEED, ARENA_LINK   master seed (7) and link preset (wifi)
  ARENA_MATCH              match id, the key prefix arena/<id>/ (a fresh one)

examples:
  arena up compose.yaml                        # the services of compose.yaml as local processes
  ARENA_HALF_TIME=30 arena up compose.yaml     # 2 x 30 s instead of 2 x 300 s
  arena up compose.yaml --json"""


def add_parser(sub) -> None:
    u = add_command(sub, "up", "start the services of a compose file as local processes (no Docker needed)", EXAMPLES)
    u.add_argument("file", help="compose.yaml")
    u.add_argument("--json", action="store_true", help="print the match result as JSON")
    u.add_argument("--timeout", type=seconds, default=600.0, metavar="S", help="give up after S seconds (600)")


def run(args: argparse.Namespace) -> int:
    from arena.match import compose

    try:
        result = compose.up(args.file, timeout=args.timeout)
    except compose.ComposeError as exc:
        print(f"arena up: error: {one_line(str(exc))}", file=sys.stderr)
        return 2 if exc.bad_input else 1
    return emit_match(result, args.json, "arena up")
