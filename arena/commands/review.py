"""`arena review FILE.mcap`: summarise a match recording."""

from __future__ import annotations

import argparse

from arena.commands._common import add_command
from arena.config import ConfigError

CATCH_SIGTERM = True

EXAMPLES = """examples:
  arena review match.mcap                    # teams, score, goals, restarts, possession, links, timing
  arena review match.mcap --json
  arena review match.mcap --plots plots/     # PNG charts and an animated GIF of the match
  arena review match.mcap --html replay.html # one self-contained HTML page that replays the match"""


def add_parser(sub) -> None:
    v = add_command(
        sub, "review", "summarise a match recording: score, goals, restarts, possession, links, timing", EXAMPLES
    )
    v.add_argument("file", help="an MCAP file written by arena match --record")
    v.add_argument("--plots", metavar="DIR", help="also write PNG charts and an animated GIF into DIR")
    v.add_argument("--goalkeepers", action="store_true", help="with --plots: keep the goalkeepers in the heatmaps")
    v.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    v.add_argument(
        "--html",
        metavar="FILE.html",
        help="also write one self-contained web page that replays the match (no network needed)",
    )


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from arena.review import review

    if args.plots and Path(args.plots).exists() and not Path(args.plots).is_dir():
        raise ConfigError(f"--plots {args.plots} exists and is not a directory")
    if args.html:
        page = Path(args.html).expanduser()
        if page.is_dir() or not page.parent.is_dir():
            raise ConfigError(f"--html {args.html}: not a file in an existing directory")
    return review.main(args.file, plots=args.plots, as_json=args.json, goalkeepers=args.goalkeepers, html=args.html)
