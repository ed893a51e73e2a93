"""A match in an interpreter of its own, handed its whole `MatchConfig`.

`python -m arena.match --engine ENGINE` reads one `MatchConfig` as JSON on stdin
(`MatchConfig.to_json`, every field: field, rules, timing, links, scenario, ...), plays it,
and prints its `MatchResult` as one JSON object on stdout (`MatchResult.to_dict`, the keys
of `arena match --json` and `referee_log`); the faults' warnings go to stderr. A tournament's
match on the processes engine, a cluster task and `arena bench throughput` start it with
`start` and read what it printed with `decode`: no flags between our own code.

Exit codes: 0 a result was printed (a void one too: `outcome` says so), 1 the match could
not be played (`MatchError`, one line on stderr), 2 the configuration was refused, 130
stopped by SIGINT (every process of the match stopped)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from arena.config import MatchConfig
    from arena.match.result import MatchResult


def argv(engine: str) -> list[str]:
    """The command that plays one match on `engine` in an interpreter of its own (this one's)."""
    return [sys.executable, "-m", "arena.match", "--engine", engine]


def start(cfg: MatchConfig, engine: str, **popen: Any) -> tuple[subprocess.Popen, str]:
    """The match's process, started, and the text to hand it on stdin (`proc.communicate(input=...)`).
    `popen`: Popen's options (stderr, start_new_session, ...); stdin and stdout are pipes, text mode."""
    proc = subprocess.Popen(argv(engine), stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, **popen)
    return proc, cfg.to_json()


def decode(out: str) -> MatchResult:
    """The `MatchResult` the match printed; ValueError if it printed none (one line)."""
    import msgspec

    from arena.match.result import MatchResult

    try:
        return msgspec.json.decode(out, type=MatchResult)
    except msgspec.DecodeError as exc:
        raise ValueError(f"the match printed no result ({str(exc).splitlines()[0]})") from None


def main(args: list[str] | None = None) -> int:
    from arena.config import ConfigError, MatchConfig
    from arena.match import MatchError, faults, play
    from arena.match.engines import ENGINES

    p = argparse.ArgumentParser(prog="python -m arena.match", description=__doc__.splitlines()[0])
    p.add_argument("--engine", choices=ENGINES, default="processes")
    engine = p.parse_args(args).engine
    try:
        cfg = MatchConfig.from_json(sys.stdin.read())
    except ConfigError as exc:
        print(f"arena.match: error: the configuration on stdin: {str(exc).splitlines()[0]}", file=sys.stderr)
        return 2
    try:
        result = play(cfg, engine=engine)
    except MatchError as exc:
        print(f"arena.match: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("arena.match: interrupted; every process of the match was stopped", file=sys.stderr)
        return 130
    for line in faults.warnings(result):
        print(f"arena.match: warning: {line}", file=sys.stderr)
    print(json.dumps(result.to_dict()))
    return 0
