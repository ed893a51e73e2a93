"""The `arena` command: one sub-command per module of arena/commands/; this only dispatches.

Bad input never ends in a traceback. Exit codes, the same for every subcommand:

* 0: done;
* 1: an internal failure: one line that names the log with the details;
* 2: a user error (a flag, a value, an endpoint, a port, a file, the
  environment): one line `arena <cmd>: error: ...` that says what to change;
* 130: interrupted (Ctrl-C); 143: terminated (SIGTERM), for the commands that
  stop a match's processes on it.
"""

from __future__ import annotations

import argparse
import atexit
import gc
import importlib
import os
import signal
import sys

from arena.commands import names
from arena.commands._common import Parser
from arena.config import ConfigError
from arena.runtime.version import package_version

_PARSERS: dict[str | None, Parser] = {}


class _Version(argparse.Action):
    """`arena --version`, looked up only when asked: importlib.metadata costs ~30 ms of every call."""

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"arena {package_version()}")  # on stdout, as argparse's own version action
        parser.exit()


def parser(only: str | None = None) -> Parser:
    """`arena` and its sub-commands' parsers: every one, or only sub-command `only` (what `main` parses
    when the first word names one: building and importing all of them took ~60 ms of every call)."""
    if only not in _PARSERS:
        top = Parser(
            prog="arena",
            description="Wheeled-robot soccer (RoboCup MSL / KRSBI-B) as separate processes over zenoh.",
            epilog="Run 'arena <command> --help' for examples.",
        )
        top.add_argument("--version", action=_Version, nargs=0, help="show the version and exit")
        sub = top.add_subparsers(dest="command", metavar="<command>", parser_class=Parser)
        sub.required = True
        for name in names():
            if only is None or name == only:
                command(name).add_parser(sub)
        _PARSERS[only] = top
    return _PARSERS[only]


def command(name: str):
    """The module of sub-command `name` (`add_parser(sub)`, `run(args) -> int`)."""
    return importlib.import_module(f"arena.commands.{name}")


class Terminated(KeyboardInterrupt):
    """SIGTERM (`kill`, a service manager): stopped and cleaned up as Ctrl-C is, exit code 143.
    The processes a match forks set SIGTERM back to its default (match/forkstart.py)."""


_TERMINATED_IN: list[int] = []  # the pid that installed `_terminated`


def _terminated(signum, frame):
    if os.getpid() not in _TERMINATED_IN:  # a child forked before it set SIGTERM back: die as by default
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    raise Terminated


def main(argv: list[str] | None = None) -> int:
    if argv is None:  # the command line: this process ends when main returns
        # The interpreter's last full collection would scan every object of every module (numpy's,
        # the strategies', ...) only to find nothing: ~12 ms of a short command. Registered first, run last.
        atexit.register(gc.freeze)
    words = sys.argv[1:] if argv is None else argv
    try:
        args = parser(words[0] if words and words[0] in names() else None).parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad flag (already said in one line)
        return exc.code if isinstance(exc.code, int) else 2
    cmd = command(args.command)
    if getattr(cmd, "CATCH_SIGTERM", False):  # tournament and run have their own
        _TERMINATED_IN.append(os.getpid())
        signal.signal(signal.SIGTERM, _terminated)
    try:
        return cmd.run(args)
    except ConfigError as exc:
        print(f"arena {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        stops = getattr(cmd, "STOPS_PROCESSES", False)  # True, or what the command stopped in its own words
        stopped = (
            f"; {stops}" if isinstance(stops, str) else "; every process of the match was stopped" if stops else ""
        )
        said, code = ("terminated", 143) if isinstance(exc, Terminated) else ("interrupted", 130)
        print(f"arena {args.command}: {said}{stopped}", file=sys.stderr)
        return code
    except BrokenPipeError:  # `arena ... | head`: the reader left; nothing to say
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as exc:  # a file or directory the user named: missing, read-only, full disk
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"arena {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # the last line of defence: one line, the details in a log
        return internal_error(args.command, exc)


def internal_error(command: str, exc: BaseException) -> int:
    """A bug, not the user's fault: the traceback goes to a log file, one line names it; exit 1."""
    import tempfile
    import traceback

    fd, path = tempfile.mkstemp(prefix=f"arena-{command}-crash-", suffix=".log")
    with os.fdopen(fd, "w") as fh:
        fh.write(f"arena {package_version()} {' '.join(sys.argv)}\n")
        traceback.print_exception(exc, file=fh)
    first = (str(exc).strip().splitlines() or [""])[0]
    print(f"arena {command}: internal error: {type(exc).__name__}: {first} (details in {path})", file=sys.stderr)
    return 1
