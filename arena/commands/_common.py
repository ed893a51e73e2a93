"""What every sub-command shares: the one-line-error parser, argparse types,
adding a sub-command with its examples, and printing a match result."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import NoReturn

from arena.runtime.config import MAX_HALF_TIME


class Parser(argparse.ArgumentParser):
    """argparse, but errors are one line and exit 2."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)


def add_command(sub, name: str, help_text: str, examples: str | None = None) -> argparse.ArgumentParser:
    """The sub-command `name`: its help is its description, its examples the epilog."""
    return sub.add_parser(
        name,
        help=help_text,
        description=help_text,
        epilog=examples,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


ENGINE_FLAG = dict(
    choices=["processes", "inprocess"],
    default="processes",
    help="processes: every process its own OS process over zenoh (default); inprocess: every node of a match "
    "in one process and one thread, driven cooperatively, with the same digests (lockstep only)",
)


def seconds(text: str) -> float:
    """argparse type: a finite, positive number of seconds."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number of seconds > 0")
    return value


def half_time(text: str) -> float:
    """argparse type: a half's length, finite, > 0 and at most MAX_HALF_TIME."""
    value = seconds(text)
    if value > MAX_HALF_TIME:
        raise argparse.ArgumentTypeError(f"{text!r}: at most {MAX_HALF_TIME:g} s per half")
    return value


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: give 1 or more")
    return value


def one_line(text: str) -> str:
    """A multi-line failure (headline, a log's tail, where the logs are) as one line."""
    lines = [line.strip() for line in text.strip().splitlines() if line.strip()]
    if len(lines) <= 1:
        return text.strip()
    head, *tail, last = lines
    return f"{head} {tail[-1]}; {last}" if tail else f"{head.rstrip(':')}; {last}"


def emit_match(result: dict, as_json: bool, prog: str = "arena match") -> int:
    """Print a match result (arena match, arena up): one JSON object, or the tables.

    Faults and keys with two senders are also printed on stderr, one line
    each. A void match (tools/launch/faults.py) exits 1 with one line naming the cause.
    """
    from arena.tools.launch import faults
    from arena.tools.review import report

    if as_json:
        result.pop("referee_log", None)
        print(json.dumps(result, indent=2))
    else:
        report.print_match(result)
    for line in faults.warnings(result):
        print(f"{prog}: warning: {line}", file=sys.stderr)
    if result.get("outcome") == "void":
        print(f"{prog}: void: {'; '.join(result['outcome_reasons'])}", file=sys.stderr)
        return 1
    return 0
