"""The `arena` command: one subcommand per job.

Bad input never ends in a traceback. Exit codes, the same for every subcommand:

* 0: done;
* 1: an internal failure: one line that names the log with the details;
* 2: a user error (a flag, a value, an endpoint, a port, a file, the
  environment): one line `arena <cmd>: error: ...` that says what to change;
* 130: interrupted (Ctrl-C).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import math
import os
import signal
import sys
from typing import NoReturn

from arena.commands import scenario as scenario_command
from arena.runtime.config import KINDS, MAX_HALF_TIME, ConfigError, MatchConfig, ProcessId

EXAMPLES = {
    "match": """examples:
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
  arena match --home BS --away BS --secure --listen tcp/127.0.0.1:7447   # the same on loopback""",
    "run": """examples:
  # the rest of the match was started with: arena match ... --listen tcp/0.0.0.0:7447 --no-secure --external a/1
  arena run robot --match m7-1234-abcdef --connect tcp/192.168.1.10:7447 --team a --robot 1
  # a secure match (it listens on 0.0.0.0): the credentials file arena match wrote for robot/a/1
  arena run robot --match m7-1234-abcdef --connect tls/192.168.1.10:7447 --team a --robot 1 \\
      --credentials robot-a-1.json5
  arena run engine --match demo --listen tcp/127.0.0.1:7448 --home BS --away AD --seed 3
  arena run router --match demo --listen tcp/0.0.0.0:7447
  arena run router --match demo --listen tls/0.0.0.0:7447 --credentials creds/   # secure: writes creds/*.json5
  # a recorder on another machine (the match was started with --record ... --external recorder)
  arena run recorder --match demo --connect tcp/192.168.1.10:7447 --record out.mcap
  # watch a running match in Foxglove (ws://127.0.0.1:8765); pause/step need arena match --live
  arena run viewer --match demo --connect tcp/192.168.1.10:7447 --port 8765
  # the RefBox bridge on the laptop the base stations reach (the match was started with --refbox ... --external refbox)
  arena run refbox --match demo --connect tcp/192.168.1.10:7447""",
    "up": """The match is compose.yaml's: 2 x 300 s of basic-static vs advance-dynamic, seed 7, link wifi,
unless the environment says otherwise (the same variables docker compose expands):
  ARENA_HOME, ARENA_AWAY   strategies of team a and team b
  ARENA_HALF_TIME          simulated seconds per half (300)
  ARENA_SEED, ARENA_LINK   master seed (7) and link preset (wifi)
  ARENA_MATCH              match id, the key prefix arena/<id>/ (a fresh one)

examples:
  arena up compose.yaml                        # the services of compose.yaml as local processes
  ARENA_HALF_TIME=30 arena up compose.yaml     # 2 x 30 s instead of 2 x 300 s
  arena up compose.yaml --json""",
    "tournament": """examples:
  arena tournament                                  # the paper's experiment: 4 strategies x 10 legs = 60 matches
  arena tournament --strategies AD,BS --legs 4 --half-time 60 --out runs/quick
  arena tournament --out runs/paper --resume        # continue after Ctrl-C or a crash
  arena tournament --link congested-wifi --jobs 2 --json
  arena tournament --ray                            # every match a task on a local Ray instance (docs/cluster.md)
  arena tournament --ray auto --out runs/big        # join the Ray cluster this node belongs to (ray start ...)
  arena tournament --ray 10.0.0.5:6379 --resume     # join the cluster whose head node is there
  arena tournament --ray auto --ray-runtime-env '{"pip": ["soccer-arena==0.1.0"]}'   # workers install it
  arena tournament --legs 10 --engine inprocess     # one worker process per core, same digests, ~2.5x faster""",
    "bench": """examples:
  arena bench match                # median rtf of 3 lockstep 2x60 s 3v3 matches
  arena bench match --runs 5 --half-time 120 --link wifi
  arena bench record               # median rtf with and without --record, and the ratio
  arena bench robot                # median us per robot control step and per F-SFM step
  arena bench throughput --runs 5  # both engines interleaved: rtf, ratio, start-up, tournament matches/hour
  arena bench learn --half-time 30 # env steps/cpu-s for 1 and 3 learners vs. the match; vector env 2 vs. 1
  arena bench nav                  # paper 1 Tables 4-6 and paper 3's SAROG/GNRON, 10 trials per scheme
  arena bench nav --trials 3 --only static,SAROG --plots navplots/
  arena bench nav --scenarios my_scenarios.toml --json   # your own scenarios (see tools/experiments/navbench/navbench.toml)""",
    "review": """examples:
  arena review match.mcap                    # teams, score, goals, restarts, possession, links, timing
  arena review match.mcap --json
  arena review match.mcap --plots plots/     # PNG charts and an animated GIF of the match
  arena review match.mcap --html replay.html # one self-contained HTML page that replays the match""",
    "facts": """examples:
  arena facts --seeds 20                             # 20 chase-and-shoot matches, 2 x 60 s, in process
  arena facts --seeds 10 --home AD --away BS         # shots, saves, blocks, stuck robots, fouls per team
  arena facts --round-robin AD,AS,BD,BS --legs 4 --half-time 120   # the paper's Table 2 and Fig. 9 ratio
  arena facts --seeds 10 --home AD --away BS --perception-latency 0  # robots that see the present
  arena facts --seeds 10 --home AD --away BS --json  # every match's facts and the totals per strategy, as JSON""",
    "replay": """examples:
  arena replay match.mcap --process robot/a/1          # re-run one process against its recorded inputs
  arena replay match.mcap --process basestation/b --json
  arena replay match.mcap --process all                # every process of the match""",
    "config": """examples:
  arena config --print > match.toml           # every key with its default, unit and meaning
  arena match --config match.toml --seed 3    # flags given on the command line win over the file
  arena config --check match.toml             # one line naming the bad key, or the whole file completed""",
    "strategies": """examples:
  arena strategies                 # every strategy, built-in or plugin, and whether it passes the conformance suite
  arena strategies AD chase        # only these (a plugin by its name too)
  arena strategies --no-check --json""",
    "schemas": """examples:
  arena schemas --check            # is schemas/README.md up to date with schemas/messages.py?
  arena schemas --write""",
}


ENGINE_FLAG = dict(
    choices=["processes", "inprocess"],
    default="processes",
    help="processes: every process its own OS process over zenoh (default); inprocess: every node of a match "
    "in one process and one thread, driven cooperatively, with the same digests (lockstep only)",
)


class Parser(argparse.ArgumentParser):
    """argparse, but errors are one line and exit 2."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)


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


def package_version() -> str:
    from importlib import metadata

    try:
        return metadata.version("soccer-arena")
    except metadata.PackageNotFoundError:
        from arena import __version__

        return __version__


def _add_match_flags(p: argparse.ArgumentParser, required: bool, seed: bool = True) -> None:
    p.add_argument("--home", required=required, metavar="STRATEGY", help="team a's strategy (name or BS/BD/AS/AD)")
    p.add_argument("--away", required=required, metavar="STRATEGY", help="team b's strategy")
    # Defaults of None: the match's own default, or --config FILE's value, applies (match_config).
    p.add_argument("--robots", type=int, default=None, metavar="N", help="robots per team, goalkeeper included (3)")
    p.add_argument(
        "--half-time",
        type=half_time,
        default=None,
        metavar="SECONDS",
        help=f"simulated half length [s], at most {MAX_HALF_TIME:g} (300)",
    )
    if seed:
        p.add_argument("--seed", type=int, default=None, metavar="N", help="master seed (0)")
    p.add_argument("--link", default=None, metavar="PRESET", help="ideal | lan | wifi | congested-wifi (ideal)")
    p.add_argument(
        "--link-param",
        action="append",
        default=[],
        metavar="CLASS.PARAM=V",
        help="override one link parameter, e.g. wifi.latency_ms=12 (repeatable)",
    )
    p.add_argument(
        "--perception-latency",
        type=int,
        default=None,
        metavar="TICKS",
        help="a robot at tick k sees the sense of tick k - TICKS (the model; changes digests), e.g. "
        "--perception-latency 0 for robots that see the present (default: timing.perception_latency, 3 = 60 ms)",
    )
    p.add_argument(
        "--batch",
        type=int,
        default=None,
        metavar="N",
        help="sense/cmd frames per message, 1..perception latency; 0 = as many as it allows (a transport "
        "detail: digests are the same for every N), e.g. --batch 1 for one frame per message (0)",
    )


def every_match_latency(p: argparse.ArgumentParser) -> None:
    """`--perception-latency` of a command that plays many matches (tournament, facts)."""
    p.add_argument(
        "--perception-latency",
        type=int,
        default=None,
        metavar="TICKS",
        help="every match's perception latency, as arena match's (default: timing.perception_latency, 3), "
        "e.g. 0 for robots that see the present",
    )


_PARSER: list[Parser] = []


def parser() -> Parser:
    """The parser, built once per process: building it takes ~40 ms, and a forked match
    process (tools/launch/forkstart.py) gets it ready-made from the launcher."""
    if not _PARSER:
        _PARSER.append(build_parser())
    return _PARSER[0]


def build_parser() -> Parser:  # noqa: PLR0915 - the argument tables of every sub-command
    top = Parser(
        prog="arena",
        description="Wheeled-robot soccer (RoboCup MSL / KRSBI-B) as separate processes over zenoh.",
        epilog="Run 'arena <command> --help' for examples.",
    )
    top.add_argument("--version", action="version", version=f"arena {package_version()}")
    sub = top.add_subparsers(dest="command", metavar="<command>", parser_class=Parser)
    sub.required = True

    def add(name: str, help_text: str) -> argparse.ArgumentParser:
        return sub.add_parser(
            name,
            help=help_text,
            description=help_text,
            epilog=EXAMPLES.get(name),
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )

    scenario_command.add_parser(sub)
    m = add("match", "play one match, every process its own OS process, and print the score")
    _add_match_flags(m, required=False)
    m.add_argument(
        "--config",
        dest="config_file",
        metavar="FILE.toml",
        help="the match's configuration: field, robot, rules, timing, links (arena config --print writes one); "
        "flags given here win",
    )
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
        help="write every principal's credentials file (DIR/robot-b-1.json5, ..., viewer.json5) here "
        "(default: the match's private temp dir)",
    )
    m.add_argument(
        "--strict",
        action="store_true",
        help="stop the match at the first failed process and exit 1 (CI, strategy development); "
        "by default a crashed robot or base station is a fault and its team plays on short-handed",
    )
    rb = m.add_argument_group("MSL RefBox (docs/refbox.md)")
    rb.add_argument(
        "--refbox",
        nargs="?",
        const="tcp/0.0.0.0:28097",
        metavar="ENDPOINT",
        help="run the RefBox bridge: base stations connect here over TCP (default tcp/0.0.0.0:28097)",
    )
    rb.add_argument(
        "--refbox-teams",
        metavar="FILE.json",
        help="team table in msl_teams.json form (UnicastAddr, Team, MulticastAddr, optional side and protocol); "
        "unknown addresses get RESET. Default: first connection is team a, the second team b",
    )
    rb.add_argument(
        "--refbox-protocol",
        action="append",
        default=[],
        metavar="TEAM=json|legacy",
        help="without a team table: the protocol of team a's or b's connection, e.g. b=legacy (json)",
    )
    rb.add_argument("--refbox-swap", action="store_true", help="team a is magenta and b cyan (default a cyan)")
    rb.add_argument(
        "--refbox-targets",
        metavar="CYAN,MAGENTA",
        help="targetTeam strings of the two colours when the team table names none (224.16.32.201,224.16.32.202)",
    )
    rb.add_argument(
        "--refbox-wait", type=int, default=0, metavar="N", help="hold the start until N base stations connected (0)"
    )
    rb.add_argument(
        "--refbox-follow",
        metavar="HOST:PORT",
        help="our referee connects to a real RefBox as a base station and mirrors its commands",
    )
    rb.add_argument(
        "--via-refbox",
        action="store_true",
        help="our base stations take referee commands over TCP from the bridge (needs --refbox and --realtime)",
    )
    m.add_argument("--engine", **ENGINE_FLAG)
    m.add_argument(
        "--live",
        nargs="?",
        type=int,
        const=8765,
        metavar="PORT",
        help="start a viewer: the Foxglove app connects to ws://127.0.0.1:PORT (8765; 0: a free port, "
        "printed); in lockstep the "
        "viewer's parameters pause, step and pace the match",
    )
    m.add_argument(
        "--pace",
        type=float,
        metavar="X",
        help="with --live in lockstep: X simulated seconds per wall second (1.0 = real time, the default "
        "with --live; 0 = as fast as it goes). It only waits: the result is the same",
    )
    m.add_argument("--live-host", default="127.0.0.1", metavar="HOST", help="with --live: the address to serve on")

    r = add("run", "start one process of a match on its own (hardware-in-the-loop)")
    r.add_argument("kind", choices=[*KINDS, "router"], help="process kind")
    r.add_argument("--match", required=True, metavar="ID", help="match id (its key prefix arena/<ID>/)")
    net = r.add_mutually_exclusive_group(required=True)
    net.add_argument("--connect", metavar="ENDPOINT", help="zenoh endpoint to connect to, e.g. tcp/10.0.0.5:7447")
    net.add_argument("--listen", metavar="ENDPOINT", help="zenoh endpoint to listen on")
    r.add_argument("--team", choices=["a", "b"], help="team (robot, basestation)")
    r.add_argument("--robot", type=int, metavar="N", help="robot number, 0 = goalkeeper (robot)")
    r.add_argument("--seed", type=int, metavar="S", help="master seed; must match the match's")
    r.add_argument("--realtime", action="store_true", help="the match runs in real-time mode")
    r.add_argument("--config", metavar="FILE", help="match configuration JSON (default: ask the engine)")
    r.add_argument("--mode", choices=["peer", "client"], default="peer", help="zenoh mode (peer)")
    r.add_argument(
        "--credentials",
        metavar="FILE",
        help="this process's credentials file from arena match (a zenoh config fragment: user, password, "
        "TLS root, MAC key); a secure match needs it. router: make the match secure and write every "
        "process's credentials file into this directory",
    )
    r.add_argument(
        "--startup-timeout", type=seconds, default=60.0, metavar="S", help="wait this long [s] for the match (60)"
    )
    r.add_argument("--log-level", default="WARNING", choices=["DEBUG", "INFO", "WARNING", "ERROR"])
    r.add_argument(
        "--record",
        metavar="PATH",
        help="recorder: write the MCAP file here; engine without --config: the match records (the path is the recorder's)",
    )
    r.add_argument("--host", default="127.0.0.1", metavar="HOST", help="viewer: the address to serve on (127.0.0.1)")
    r.add_argument(
        "--port", type=int, metavar="PORT", help="viewer: the Foxglove WebSocket port (the match's, or 8765)"
    )
    eng = r.add_argument_group("engine only: the match it hosts when no --config is given")
    _add_match_flags(eng, required=False, seed=False)

    u = add("up", "start the services of a compose file as local processes (no Docker needed)")
    u.add_argument("file", help="compose.yaml")
    u.add_argument("--json", action="store_true", help="print the match result as JSON")
    u.add_argument("--timeout", type=seconds, default=600.0, metavar="S", help="give up after S seconds (600)")

    t = add("tournament", "round-robin of strategies: the paper's tables, charts and ratings")
    t.add_argument("--strategies", default="AD,AS,BD,BS", metavar="A,B,...", help="strategies (AD,AS,BD,BS)")
    t.add_argument(
        "--legs", type=positive_int, default=10, metavar="N", help="matches per pairing, home and away alternating (10)"
    )
    t.add_argument(
        "--half-time", type=half_time, default=300.0, metavar="SECONDS", help="simulated half length [s] (300)"
    )
    t.add_argument("--robots", type=int, default=3, metavar="N", help="robots per team (3)")
    t.add_argument("--link", default="ideal", metavar="PRESET", help="link preset (ideal)")
    t.add_argument(
        "--link-param", action="append", default=[], metavar="CLASS.PARAM=V", help="override a link parameter"
    )
    every_match_latency(t)
    t.add_argument("--seed", type=int, default=0, metavar="N", help="tournament seed; match seeds derive from it (0)")
    t.add_argument("--jobs", type=int, default=0, metavar="N", help="matches at once (default: one per core)")
    t.add_argument("--out", default="tournament", metavar="DIR", help="results directory (tournament)")
    t.add_argument("--resume", action="store_true", help="skip the matches already finished in --out")
    t.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        metavar="ADDRESS",
        help="play every match as a Ray task: alone, a local Ray instance; auto or HOST:PORT, join that cluster "
        "(needs pip install 'soccer-arena[cluster]'; docs/cluster.md)",
    )
    t.add_argument(
        "--ray-runtime-env",
        metavar="JSON",
        help='with --ray: a Ray runtime_env for the workers, e.g. \'{"pip": ["soccer-arena==0.1.0"]}\'',
    )
    t.add_argument("--json", action="store_true", help="print one JSON object")
    t.add_argument("--engine", **ENGINE_FLAG)

    b = add("bench", "benchmarks: print throughput and ratios (medians of several runs)")
    b.add_argument(
        "what",
        choices=["match", "record", "robot", "nav", "throughput", "learn"],
        help="match: speed; record: the cost of --record; robot: us per robot control step and F-SFM step; "
        "nav: the navigators in their papers' scenarios; throughput: both engines (--engine) interleaved, "
        "side by side; learn: env steps vs. in-process match ticks per CPU-second, and the vector env "
        "on 2 workers vs. 1 (needs the learn extra)",
    )
    b.add_argument(
        "--strategy", default="advance-dynamic", metavar="NAME", help="robot, throughput: strategy (both teams) (AD)"
    )
    b.add_argument("--runs", type=positive_int, default=3, metavar="N", help="runs (3)")
    b.add_argument("--half-time", type=half_time, default=60.0, metavar="SECONDS", help="half length [s] (60)")
    b.add_argument("--robots", type=int, default=3, metavar="N")
    b.add_argument("--link", default="ideal", metavar="PRESET")
    b.add_argument("--json", action="store_true")
    b.add_argument(
        "--trials", type=positive_int, default=10, metavar="N", help="nav: trials per scheme and scenario (10)"
    )
    b.add_argument("--seed", type=int, default=0, metavar="N", help="nav: seed of the trials' noise (0)")
    b.add_argument(
        "--scenarios",
        metavar="FILE",
        help="nav: scenario file (default: the built-in tools/experiments/navbench/navbench.toml)",
    )
    b.add_argument("--only", action="append", metavar="NAME[,NAME]", help="nav: run only these scenarios")
    b.add_argument("--plots", metavar="DIR", help="nav: also write PNG trajectory plots into DIR")

    fa = add("facts", "play matches in process and measure them: rules and team-play facts per match and strategy")
    fa.add_argument("--seeds", type=int, default=20, metavar="N", help="matches, seeds first-seed.. (20)")
    fa.add_argument("--first-seed", type=int, default=0, metavar="S", help="first seed (0)")
    fa.add_argument(
        "--half-time", type=half_time, default=60.0, metavar="SECONDS", help="simulated half length [s] (60)"
    )
    fa.add_argument("--home", default="chase", metavar="NAME", help="team a's strategy (chase)")
    fa.add_argument("--away", default="chase", metavar="NAME", help="team b's strategy (chase)")
    fa.add_argument("--workers", type=int, default=0, metavar="N", help="matches at once (default: up to 2)")
    fa.add_argument("--round-robin", metavar="A,B,...", help="instead: every pairing of these strategies --legs times")
    fa.add_argument("--legs", type=int, default=4, metavar="N", help="round robin: matches per pairing (4)")
    fa.add_argument("--seed", type=int, default=0, metavar="N", help="round robin: the tournament seed (0)")
    fa.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    every_match_latency(fa)

    v = add("review", "summarise a match recording: score, goals, restarts, possession, links, timing")
    v.add_argument("file", help="an MCAP file written by arena match --record")
    v.add_argument("--plots", metavar="DIR", help="also write PNG charts and an animated GIF into DIR")
    v.add_argument("--goalkeepers", action="store_true", help="with --plots: keep the goalkeepers in the heatmaps")
    v.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    v.add_argument(
        "--html",
        metavar="FILE.html",
        help="also write one self-contained web page that replays the match (no network needed)",
    )

    y = add("replay", "re-run one process against its recorded inputs and compare its outputs")
    y.add_argument("file", help="an MCAP file written by arena match --record (lockstep)")
    y.add_argument(
        "--process",
        action="append",
        required=True,
        metavar="PROC",
        help="robot/a/1 (or a/1), basestation/b, engine, referee, or all (repeatable)",
    )
    y.add_argument("--json", action="store_true", help="print JSON instead of text")

    cf = add("config", "the match configuration file: print the defaults, or check a file (arena match --config)")
    cg = cf.add_mutually_exclusive_group(required=True)
    cg.add_argument("--print", dest="print_defaults", action="store_true", help="write the defaults as TOML to stdout")
    cg.add_argument("--check", metavar="FILE.toml", help="validate FILE and print it completed with the defaults")

    st = add("strategies", "list the strategies: built-ins and installed plugins, with their conformance status")
    st.add_argument("names", nargs="*", metavar="NAME", help="only these strategies (names or aliases)")
    st.add_argument("--no-check", action="store_true", help="skip the conformance suite (~1.5 s per strategy)")
    st.add_argument("--json", action="store_true", help="print one JSON object")

    s = add("schemas", "the wire contract: check or rewrite schemas/README.md from schemas/messages.py")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--check", action="store_true", help="exit 1 if schemas/README.md is stale")
    g.add_argument("--write", action="store_true", help="rewrite schemas/README.md")
    return top


def match_config(
    args: argparse.Namespace, realtime: bool = False, external=(), tap: bool = False, refbox=None
) -> MatchConfig:
    from arena.runtime.links import parse_override, resolve
    from arena.strategies import registry

    overrides: dict[str, dict[str, float]] = {}
    for text in args.link_param:
        cls, param, value = parse_override(text)
        overrides.setdefault(cls, {})[param] = value
    base = MatchConfig()
    if getattr(args, "config_file", None):
        from arena.runtime import matchfile

        base = matchfile.load(args.config_file)
    link = args.link if args.link is not None else base.link
    if args.link is None:  # the file's overrides, then the flags' on top
        merged = {cls: dict(ps) for cls, ps in base.link_overrides.items()}
        for cls, ps in overrides.items():
            merged.setdefault(cls, {}).update(ps)
        overrides = merged
    resolve(link, overrides)  # validates preset, classes and values
    home = registry.resolve_name(args.home or base.home)
    away = registry.resolve_name(args.away or base.away)
    timing = base.timing
    if getattr(args, "perception_latency", None) is not None:
        timing = dataclasses.replace(timing, perception_latency=args.perception_latency)
    if getattr(args, "batch", None) is not None:
        timing = dataclasses.replace(timing, batch=args.batch)
    cfg = base.replace(
        timing=timing,
        seed=args.seed if args.seed is not None else base.seed,
        home=home,
        away=away,
        robots=args.robots if args.robots is not None else base.robots,
        half_time=args.half_time if args.half_time is not None else base.half_time,
        link=link,
        link_overrides=overrides,
        realtime=realtime,
        tap=tap,
        **({"refbox": refbox} if refbox is not None else {}),
        external=tuple(
            ProcessId.parse(e).short if ProcessId.parse(e).kind == "robot" else str(ProcessId.parse(e))
            for e in external
        ),
    )
    cfg.validate()
    return cfg


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


def warn_unreachable_refbox(endpoint: str) -> None:
    """Said before the match starts, not only in its report: the referee keeps trying while it plays."""
    from arena.rules import refbox_protocol as rp
    from arena.rules.refbox_client import unreachable

    host, port = rp.parse_endpoint(endpoint)
    if why := unreachable(host, port):
        print(
            f"arena match: warning: --refbox-follow {endpoint}: cannot connect ({why}); the match starts and the "
            "referee keeps trying, but until the RefBox answers nobody restarts play (never connected: the match is void)",
            file=sys.stderr,
        )


def cmd_match(args: argparse.Namespace) -> int:
    from arena.tools.launch import launcher

    missing = [f for f, v in (("--home", args.home), ("--away", args.away)) if v is None]
    if missing and not args.config_file:
        raise ConfigError(f"the following arguments are required: {', '.join(missing)} (or give them in --config FILE)")
    record = record_path(args.record, fresh=True) if args.record else ""
    cfg = match_config(
        args, realtime=args.realtime, external=args.external, tap=bool(record), refbox=refbox_params(args)
    )
    cfg = live_config(cfg, args.live, args.pace, args.live_host)
    if args.match:
        from arena.schemas.keys import check_match_id

        try:
            check_match_id(args.match)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    if args.startup_timeout is not None or cfg.external:
        import dataclasses

        timeout = args.startup_timeout if args.startup_timeout is not None else 600.0
        cfg = cfg.replace(timing=dataclasses.replace(cfg.timing, startup_timeout=timeout))
    if args.engine == "inprocess":
        return match_inprocess(args, cfg, record)
    if cfg.refbox.follow:
        warn_unreachable_refbox(cfg.refbox.follow)
    show = not args.json and sys.stderr.isatty()
    try:
        result = launcher.play_match(
            cfg,
            match=args.match,
            listen=args.listen,
            progress=show,
            log_dir=args.logs,
            announce=lambda text: print(text, file=sys.stderr, flush=True),
            strict=args.strict,
            live_host=args.live_host,
            secure=args.secure,
            credentials=args.credentials,
            record=record,
        )
    except launcher.MatchError as exc:
        print(f"arena match: error: {one_line(str(exc))}", file=sys.stderr)
        return 2 if isinstance(exc, launcher.JoinError) else 1
    return emit_match(result, args.json)


def refbox_params(args: argparse.Namespace):
    """The RefBox flags of `arena match` as `RefboxParams` (None without any); bad values are a ConfigError."""
    from pathlib import Path

    from arena.rules import refbox_protocol as rp
    from arena.runtime.config import RefboxParams

    changes: dict[str, object] = {}
    try:
        if args.refbox:
            from arena.rules.refbox_server import check_listen

            check_listen(args.refbox)
            changes["listen"] = args.refbox
        if args.refbox_teams:
            try:
                text = Path(args.refbox_teams).read_text()
            except OSError as exc:
                raise ConfigError(f"cannot read --refbox-teams {args.refbox_teams}: {exc.strerror}") from None
            changes["teams"] = rp.parse_team_table(text)
        for item in args.refbox_protocol:
            team, _, proto = item.partition("=")
            if team not in ("a", "b") or proto not in rp.PROTOCOLS:
                raise ConfigError(f"--refbox-protocol {item!r}: use a=json, a=legacy, b=json or b=legacy")
            changes[f"protocol_{team}"] = proto
        if args.refbox_targets:
            cyan, _, magenta = args.refbox_targets.partition(",")
            if not cyan or not magenta or cyan == magenta:
                raise ConfigError(f"--refbox-targets {args.refbox_targets!r}: two different strings, CYAN,MAGENTA")
            changes["target_cyan"], changes["target_magenta"] = cyan, magenta
        if args.refbox_follow:
            rp.parse_endpoint(args.refbox_follow)
            changes["follow"] = args.refbox_follow
    except rp.ProtocolError as exc:
        raise ConfigError(str(exc)) from None
    if args.refbox_swap:
        changes["swap"] = True
    if args.refbox_wait:
        changes["wait"] = args.refbox_wait
    if args.via_refbox:
        changes["via"] = True
    if args.refbox_wait and not args.refbox:
        raise ConfigError("--refbox-wait needs --refbox")
    # No RefBox flag: keep what a --config file says (or the defaults).
    return RefboxParams(**changes) if changes else None


def one_line(text: str) -> str:
    """A multi-line failure (headline, a log's tail, where the logs are) as one line."""
    lines = [line.strip() for line in text.strip().splitlines() if line.strip()]
    if len(lines) <= 1:
        return text.strip()
    head, *tail, last = lines
    return f"{head} {tail[-1]}; {last}" if tail else f"{head.rstrip(':')}; {last}"


def match_inprocess(args: argparse.Namespace, cfg: MatchConfig, record: str = "") -> int:
    """`arena match --engine inprocess`: flags that need separate processes are refused."""
    from arena.tools.launch import inprocess

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
        result = inprocess.play_match(cfg, record=record)
    except inprocess.InprocessError as exc:
        print(f"arena match: error: {one_line(str(exc))}", file=sys.stderr)
        return 1
    return emit_match(result, args.json)


def live_config(cfg: MatchConfig, live: int | None, pace: float | None, host: str = "127.0.0.1") -> MatchConfig:
    """`--live [PORT]` and `--pace X`: a viewer, and in lockstep a paced, pausable engine."""
    import dataclasses
    import socket

    if live is None:
        if pace is not None:
            raise ConfigError("--pace needs --live")
        return cfg
    if pace is not None and cfg.realtime:
        raise ConfigError("--pace applies to lockstep; --realtime already plays at the wall clock's speed")
    pace = 0.0 if cfg.realtime else (1.0 if pace is None else pace)
    if 0 <= live <= 65535:
        # A port in use would stop the viewer after every other process had started: say so now.
        # Port 0 is a free port chosen here, so the address printed is the one to connect to.
        with socket.socket() as s:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                s.bind((host, live))
            except OSError as exc:
                raise ConfigError(f"--live {live}: cannot serve on {host}:{live}: {exc.strerror}") from None
            live = s.getsockname()[1]
    timing = cfg.timing
    if not cfg.realtime:
        # Everybody waits while the viewer pauses the engine: a pause is not a failure.
        timing = dataclasses.replace(timing, wait_timeout=max(timing.wait_timeout, 3600.0))
    return cfg.replace(live=live, pace=pace, timing=timing)


def record_path(text: str, fresh: bool = False) -> str:
    """An absolute path for a new MCAP file whose directory exists (children may run elsewhere).

    `fresh`: an existing file is refused, not overwritten (arena match; the recorder
    it starts gets the path it checked)."""
    from pathlib import Path

    path = Path(text).expanduser().resolve()
    if not path.parent.is_dir():
        raise ConfigError(f"--record {text}: directory {path.parent} does not exist")
    if path.is_dir():
        raise ConfigError(f"--record {text} is a directory")
    if fresh and path.exists():
        size = path.stat().st_size / 1e6
        raise ConfigError(f"--record {text} exists ({size:.1f} MB): give a new file name, or delete it first")
    # Tried now, not by the recorder after the match has started: a recorder that
    # cannot write holds every process at the start barrier until it times out.
    existed = path.exists()
    try:
        with open(path, "ab"):
            pass
    except OSError as exc:
        raise ConfigError(f"--record {text}: cannot write it ({exc.strerror or exc})") from None
    if not existed:
        path.unlink()
    return str(path)


def cmd_run(args: argparse.Namespace) -> int:
    from arena.runtime.session import NetConfig
    from arena.tools.launch import run as runner

    logging.basicConfig(
        level=args.log_level, format="%(asctime)s %(name)s %(levelname)s %(message)s", stream=sys.stderr
    )
    net = NetConfig(
        mode=args.mode,
        connect=(args.connect,) if args.connect else (),
        listen=(args.listen,) if args.listen else (),
    )
    if args.kind == "router":
        return runner.main_guarded(runner.run_router, args.match, net, args.credentials)
    keyring = None
    try:
        pid = runner.process_id(args.kind, args.team, args.robot)
        if args.credentials:
            import dataclasses

            base, mode, keyring = runner.load_credentials(args.credentials, pid, args.match, wait=10.0)
            net = dataclasses.replace(net, base=base, mode=mode or net.mode)
        cfg = None
        if args.config:
            cfg = runner.load_config(args.config)
        elif args.kind == "engine":
            # The engine only needs to know that the match records; the path is the recorder's.
            cfg = match_config(args, realtime=args.realtime, tap=bool(args.record))
        if args.record and args.kind not in ("engine", "recorder"):
            raise ConfigError(f"--record does not apply to {args.kind}")
        if args.port is not None and (args.kind != "viewer" or not 0 <= args.port <= 65535):
            raise ConfigError("--port applies to the viewer only, 0..65535")
        record = record_path(args.record) if args.record and args.kind == "recorder" else None
        from arena.schemas.keys import check_match_id

        check_match_id(args.match)
    except (ConfigError, ValueError) as exc:
        print(f"arena run: error: {exc}", file=sys.stderr)
        return 2
    return runner.main_guarded(
        runner.run,
        pid,
        args.match,
        net,
        cfg,
        args.seed,
        args.realtime,
        args.startup_timeout,
        record,
        args.host,
        args.port,
        keyring,
    )


def cmd_up(args: argparse.Namespace) -> int:
    from arena.tools.launch import compose

    try:
        result = compose.up(args.file, timeout=args.timeout)
    except compose.ComposeError as exc:
        print(f"arena up: error: {one_line(str(exc))}", file=sys.stderr)
        return 2 if exc.bad_input else 1
    return emit_match(result, args.json, "arena up")


def cmd_tournament(args: argparse.Namespace) -> int:
    from pathlib import Path

    from arena.runtime.links import parse_override, resolve
    from arena.strategies import registry
    from arena.tools.experiments import tournament

    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise ConfigError(f"--out {args.out} exists and is not a directory")
    names = [registry.resolve_name(s) for s in args.strategies.split(",") if s.strip()]
    if len(set(names)) < 2:
        raise ConfigError("--strategies needs at least two different strategies")
    if args.legs < 1 or args.jobs < 0 or args.half_time <= 0 or not 1 <= args.robots <= 6:
        raise ConfigError("--legs >= 1, --jobs >= 0, --half-time > 0 and --robots 1..6, please")
    overrides: dict[str, dict[str, float]] = {}
    for text in args.link_param:
        cls, param, value = parse_override(text)
        overrides.setdefault(cls, {})[param] = value
    resolve(args.link, overrides)
    if args.perception_latency is not None:  # its range, as arena match checks it
        from arena.runtime.config import MatchConfig, TimingParams

        MatchConfig(timing=TimingParams(perception_latency=args.perception_latency)).validate()
    if args.ray is not None:
        from arena.tools.experiments.cluster import parse_address, parse_runtime_env

        parse_address(args.ray)
        parse_runtime_env(args.ray_runtime_env)
    elif args.ray_runtime_env is not None:
        raise ConfigError("--ray-runtime-env needs --ray")
    opts = tournament.TournamentOptions(
        strategies=tuple(names),
        legs=args.legs,
        half_time=args.half_time,
        robots=args.robots,
        link=args.link,
        link_param=tuple(args.link_param),
        perception_latency=args.perception_latency,
        seed=args.seed,
        jobs=args.jobs,
        out=Path(args.out),
        resume=args.resume,
        json=args.json,
        engine=args.engine,
        ray=args.ray,
        ray_runtime_env=args.ray_runtime_env,
    )
    summary, interrupted = tournament.run(opts)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        tournament.print_summary(summary)
    if interrupted:
        print("arena tournament: interrupted; finished matches are kept (continue with --resume)", file=sys.stderr)
        return 130
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    from arena.strategies import registry
    from arena.tools.experiments import bench

    if args.what in ("match", "record", "throughput"):  # checked before the first run says it starts
        from arena.runtime.links import resolve

        resolve(args.link, {})
        MatchConfig(robots=args.robots, half_time=args.half_time, link=args.link).validate()
        if args.what == "throughput":  # its matches are `arena match` commands: a bad name would fail in each
            registry.resolve_name(args.strategy)
    if args.what == "record":
        return bench.bench_record(args.runs, args.half_time, args.robots, args.link, args.json)
    if args.what == "robot":
        return bench.bench_robot(args.strategy, args.json)
    if args.what == "learn":
        registry.resolve_name(args.strategy)
        try:
            from arena.learn.bench import bench_learn
        except ImportError as exc:
            raise ConfigError(str(exc)) from None
        return bench_learn(args.runs, args.half_time, args.strategy, args.json)
    if args.what == "throughput":
        from arena.tools.experiments import throughput

        return throughput.bench_throughput(args.runs, args.half_time, args.robots, args.link, args.strategy, args.json)
    if args.what == "nav":
        from arena.tools.experiments import navbench

        return navbench.main(
            scenarios=args.scenarios,
            only=args.only or (),
            trials=args.trials,
            seed=args.seed,
            plots=args.plots,
            as_json=args.json,
        )
    return bench.bench_match(args.runs, args.half_time, args.robots, args.link, args.json)


def cmd_review(args: argparse.Namespace) -> int:
    from pathlib import Path

    from arena.tools.review import review

    if args.plots and Path(args.plots).exists() and not Path(args.plots).is_dir():
        raise ConfigError(f"--plots {args.plots} exists and is not a directory")
    if args.html:
        page = Path(args.html).expanduser()
        if page.is_dir() or not page.parent.is_dir():
            raise ConfigError(f"--html {args.html}: not a file in an existing directory")
    return review.main(args.file, plots=args.plots, as_json=args.json, goalkeepers=args.goalkeepers, html=args.html)


def cmd_facts(args: argparse.Namespace) -> int:
    from arena.tools.experiments import facts

    if args.round_robin is not None and len({s.strip() for s in args.round_robin.split(",") if s.strip()}) < 2:
        raise ConfigError(f"--round-robin {args.round_robin}: needs at least two different strategies")
    return facts.main(
        seeds=args.seeds,
        first_seed=args.first_seed,
        half_time=args.half_time,
        home=args.home,
        away=args.away,
        workers=args.workers or None,
        round_robin_of=[s for s in (args.round_robin or "").split(",") if s] or None,
        legs=args.legs,
        seed=args.seed,
        perception_latency=args.perception_latency,
        as_json=args.json,
    )


def cmd_replay(args: argparse.Namespace) -> int:
    from arena.tools.review import replay

    return replay.main(args.file, args.process, as_json=args.json)


def cmd_config(args: argparse.Namespace) -> int:
    from arena.runtime import matchfile

    cfg = matchfile.load(args.check) if args.check else None
    sys.stdout.write(matchfile.dump(cfg))
    return 0


def cmd_strategies(args: argparse.Namespace) -> int:
    from arena.strategies import registry

    wanted = {registry.resolve_name(n) for n in args.names}
    rows = [r for r in registry.describe(check=not args.no_check, only=wanted or None)]
    if args.json:
        print(json.dumps({"strategies": rows}, indent=2))
        return 0
    from rich.markup import escape
    from rich.table import Table

    from arena.tools.console import console as make_console

    t = Table(title="strategies (arena match --home NAME --away ALIAS)")
    for col in ("name", "alias", "from", "conformance"):
        t.add_column(col)
    for r in rows:
        t.add_row(r["name"], "/".join(r["aliases"]) or "-", escape(r["source"]), escape(r["conformance"]))
    make_console().print(t)
    return 0 if not any(r["conformance"].startswith("fails") for r in rows) else 1


def cmd_schemas(args: argparse.Namespace) -> int:
    from arena.schemas import contract

    return contract.main(check=args.check, write=args.write)


class Terminated(KeyboardInterrupt):
    """SIGTERM (`kill`, a service manager): stopped and cleaned up as Ctrl-C is, exit code 143.
    The processes a match forks set SIGTERM back to its default (tools/launch/forkstart.py)."""


_TERMINATED_IN: list[int] = []  # the pid that installed `_terminated`


def _terminated(signum, frame):
    if os.getpid() not in _TERMINATED_IN:  # a child forked before it set SIGTERM back: die as by default
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    raise Terminated


def main(argv: list[str] | None = None) -> int:
    try:
        args = parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad flag (already said in one line)
        return exc.code if isinstance(exc.code, int) else 2
    handlers = {
        "match": cmd_match,
        "run": cmd_run,
        "up": cmd_up,
        "bench": cmd_bench,
        "schemas": cmd_schemas,
        "strategies": cmd_strategies,
        "config": cmd_config,
        "tournament": cmd_tournament,
        "review": cmd_review,
        "facts": cmd_facts,
        "replay": cmd_replay,
        "scenario": scenario_command.run,
    }
    if args.command in ("match", "up", "bench", "facts", "review"):  # tournament and run have their own
        _TERMINATED_IN.append(os.getpid())
        signal.signal(signal.SIGTERM, _terminated)
    try:
        return handlers[args.command](args)
    except ConfigError as exc:
        print(f"arena {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        stopped = (
            "; every process of the match was stopped" if args.command in ("match", "up", "facts", "bench") else ""
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
    except Exception as exc:
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
