"""What every sub-command shares: the one-line-error parser, argparse types,
adding a sub-command with its examples, and printing a match result."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING, NoReturn

if TYPE_CHECKING:
    from arena.match.result import MatchResult


class Parser(argparse.ArgumentParser):
    """argparse, but errors are one line and exit 2; no abbreviated flags (`--half 5` is not
    `--half-time 5`); an unknown flag is named by its sub-command, with the closest real one."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)  # sub-commands' parsers are made by add_parser: this class too
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)

    def parse_args(self, args=None, namespace=None):  # type: ignore[override]
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            self.unrecognized(parsed, extras)
        return parsed

    def unrecognized(self, parsed: argparse.Namespace, extras: list[str]) -> NoReturn:
        """argparse says this from the top (`see arena --help`): say it from the sub-command that was given."""
        import difflib

        owner: argparse.ArgumentParser = self
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                owner = action.choices.get(getattr(parsed, action.dest, None), owner)
        flags = [o for a in owner._actions for o in a.option_strings if o.startswith("--")]
        given = next((e for e in extras if e.startswith("--")), "").split("=", 1)[0]
        # An abbreviation names the flag it abbreviates; a typo the closest spelling, if one is close.
        close = [f for f in flags if given and f.startswith(given)][:1] or (
            difflib.get_close_matches(given, flags, n=1, cutoff=0.8) if given else []
        )
        owner.error(f"unrecognized arguments: {' '.join(extras)}" + (f"; did you mean {close[0]}?" if close else ""))


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


def emit_match(match: MatchResult, as_json: bool, prog: str = "arena match") -> int:
    """Print a match result (arena match, arena up): one JSON object, or the tables.

    Faults and keys with two senders are also printed on stderr, one line
    each. A void match (match/faults.py) exits 1 with one line naming the cause.
    """
    from arena.match import faults

    if as_json:
        printed = match.to_dict()
        printed.pop("referee_log", None)
        print(json.dumps(printed, indent=2))
    else:  # the tables need rich (~25 ms of imports): not for --json
        from arena.review import report

        report.print_match(match)
    for line in faults.warnings(match):
        print(f"{prog}: warning: {line}", file=sys.stderr)
    if match.outcome == "void":
        print(f"{prog}: void: {'; '.join(match.outcome_reasons)}", file=sys.stderr)
        return 1
    return 0


def ray_flag(p: argparse.ArgumentParser) -> None:
    """`--ray [ADDRESS]` of a command that plays many matches (tournament, experiment run, compare, tune)."""
    p.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        metavar="ADDRESS",
        help="play every match as a Ray task: alone, a local Ray instance; auto or HOST:PORT, join that cluster "
        "(needs pip install 'soccer-arena[cluster]'; docs/cluster.md)",
    )
