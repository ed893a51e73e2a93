"""`arena match`: play one match, every process its own OS process (or every
node in this one), and print the score."""

from __future__ import annotations

import argparse
import sys

from arena.commands._common import ENGINE_FLAG, add_command, emit_match, one_line, seconds
from arena.commands._live import add_live_flags, full_config
from arena.commands._match_flags import add_match_flags, allow_pickle_flag
from arena.commands._refbox_flags import add_refbox_flags, warn_unreachable_refbox
from arena.config import ConfigError, MatchConfig

CATCH_SIGTERM = True  # SIGTERM stops it as Ctrl-C does (exit 143)
STOPS_PROCESSES = True  # an interruption says every process of the match was stopped

EXAMPLES = """examples:
  arena match --home basic-static --away advance-dynamic --half-time 60 --seed 7
  arena match --home BS --away BS --half-time 30 --seed 7 --json
  arena match --home AD --away BS --link congested-wifi --link-param wifi.latency_ms=30
  arena match --home BS --away BS --external a/1      # start robot a/1 by hand (HIL)
  arena match --home BS --away BS --realtime --half-time 5
  arena match --config match.toml      # field, robot, rules, timing, links from a file (arena config --print)
  arena match --home BS --away AD --half-time 60 --record match.mcap   # then: arena review match.mcap
  arena match --home BS --away BS --half-time 10 --strict   # any crashed process ends the match, exit 1
  arena match --home BS --away BS --realtime --half-time 300 --refbox   # base stations connect to TCP 28097
  arena match --home BS --away BS --realtime --refbox tcp/0.0.0.0:28097 --refbox-protocol b=legacy --record m.mcap
  arena match --home BS --away BS --refbox --refbox-teams msl_teams.json --refbox-wait 2 --realtime
  arena match --home BS --away BS --realtime --refbox-follow 192.168.1.2:28097   # a human runs the RefBox
  arena match --home BS --away AD --realtime --half-time 30 --refbox --via-refbox   # ours through the bridge
  arena match --home AD --away AD --half-time 60 --engine inprocess    # every node in one process, same digests

  arena match --home BS --away AD --half-time 60 --live          # watch in Foxglove: ws://127.0.0.1:8765
  arena match --home BS --away AD --live 9000 --pace 4           # four times real time, port 9000
  arena match --home BS --away BS --realtime --half-time 5 --live --live-host 0.0.0.0
  # on the lab network: secure (TLS, a password per process, access control) as it listens on 0.0.0.0
  arena match --home BS --away BS --listen tcp/0.0.0.0:7447 --external a/1 --credentials creds/
  arena match --home BS --away BS --secure --listen tcp/127.0.0.1:7447   # the same on loopback"""


def add_parser(sub) -> None:
    m = add_command(sub, "match", "play one match, every process its own OS process, and print the score", EXAMPLES)
    add_match_flags(m, config=True)
    allow_pickle_flag(m)
    m.add_argument("--realtime", action="store_true", help="pace to the wall clock (HIL, live viewing)")
    m.add_argument(
        "--external", action="append", default=[], metavar="PROC", help="leave PROC (e.g. a/1) to be started by hand"
    )
    m.add_argument("--listen", metavar="ENDPOINT", help="router endpoint (default: a unix socket in a temp dir)")
    m.add_argument("--match", metavar="ID", help="match id, i.e. key prefix arena/<ID>/ (default: a fresh one)")
    m.add_argument("--logs", metavar="DIR", help="keep every process's log in DIR")
    m.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    m.add_argument(
        "--startup-timeout",
        type=seconds,
        default=None,
        metavar="S",
        help="wait this long [s] for processes to come up (30; 600 with --external)",
    )
    m.add_argument(
        "--record",
        metavar="FILE.mcap",
        help="record every message, a Foxglove scene and the configuration to a new file (an existing one is refused)",
    )
    m.add_argument(
        "--secure",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="every process a zenoh user with its own password, key-level access control generated from the key "
        "table, TLS with a fresh CA on TCP (default: on when --listen is not a loopback address)",
    )
    m.add_argument(
        "--credentials",
        metavar="DIR",
        help="every principal's credentials file (DIR/robot-b-1.json5, ..., viewer.json5), provisioned once: "
        "what DIR holds is kept, only what is missing is made (arena credentials; default: the match's "
        "private temp dir, gone with it)",
    )
    m.add_argument(
        "--strict",
        action="store_true",
        help="stop the match at the first failed process and exit 1 (CI, strategy development); "
        "by default a crashed robot or base station is a fault and its team plays on short-handed",
    )
    add_refbox_flags(m)
    m.add_argument("--engine", **ENGINE_FLAG)
    add_live_flags(m)


def run(args: argparse.Namespace) -> int:
    from arena.match import JoinError, MatchError, Processes, play

    cfg, record = full_config(args)
    if args.engine == "inprocess":
        return match_inprocess(args, cfg, record)
    if cfg.refbox.follow:
        warn_unreachable_refbox(cfg.refbox.follow)
    show = not args.json and sys.stderr.isatty()
    engine = Processes(
        match=args.match,
        listen=args.listen,
        progress=show,
        log_dir=args.logs,
        announce=lambda text: print(text, file=sys.stderr, flush=True),
        strict=args.strict,
        live_host=args.live_host,
        secure=args.secure,
        credentials=args.credentials,
    )
    try:
        result = play(cfg, engine=engine, record=record)
    except MatchError as exc:
        print(f"arena match: error: {one_line(str(exc))}", file=sys.stderr)
        return 2 if isinstance(exc, JoinError) else 1
    return emit_match(result, args.json)


def match_inprocess(args: argparse.Namespace, cfg: MatchConfig, record: str = "") -> int:
    """`arena match --engine inprocess`: flags that need separate processes are refused."""
    from arena.match import InProcess, MatchError, play

    for flag, given in (
        ("--realtime", args.realtime),
        ("--external", args.external),
        ("--listen", args.listen),
        ("--match", args.match),
        ("--logs", args.logs),
        ("--refbox", args.refbox),
        ("--refbox-follow", args.refbox_follow),
        ("--live", args.live is not None),
    ):
        if given:
            raise ConfigError(f"{flag} needs --engine processes (inprocess plays lockstep in one process)")
    try:
        result = play(cfg, engine=InProcess(last=True), record=record)  # this process ends with the match
    except MatchError as exc:
        print(f"arena match: error: {one_line(str(exc))}", file=sys.stderr)
        return 1
    return emit_match(result, args.json)
