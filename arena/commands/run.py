"""`arena run <kind>`: start one process of a match on its own (hardware in the loop)."""

from __future__ import annotations

import argparse
import os
import sys

from arena.commands._common import add_command, seconds
from arena.commands._match_flags import add_match_flags, allow_pickle_flag, match_config
from arena.config import KINDS, ConfigError

EXAMPLES = """examples:
  # the rest of the match was started with: arena match ... --listen tcp/0.0.0.0:7447 --no-secure --external a/1
  arena run robot --match m7-1234-abcdef --connect tcp/192.168.1.10:7447 --team a --robot 1
  # a secure match (it listens on 0.0.0.0): the credentials file arena match wrote for robot/a/1
  arena run robot --match m7-1234-abcdef --connect tls/192.168.1.10:7447 --team a --robot 1 \\
      --credentials robot-a-1.json5
  # a robot that plays a learned policy (the match: --home policy:/runs/p.onnx); its own copy of the file
  arena run robot --match demo --connect tcp/192.168.1.10:7447 --team a --robot 1 --policy p.onnx
  arena run engine --match demo --listen tcp/127.0.0.1:7448 --home BS --away AD --seed 3
  arena run router --match demo --listen tcp/0.0.0.0:7447
  arena run router --match demo --listen tls/0.0.0.0:7447 --credentials creds/   # secure: writes creds/*.json5
  # a recorder on another machine (the match was started with --record ... --external recorder)
  arena run recorder --match demo --connect tcp/192.168.1.10:7447 --record out.mcap
  # watch a running match in Foxglove (ws://127.0.0.1:8765); pause/step need arena match --live
  arena run viewer --match demo --connect tcp/192.168.1.10:7447 --port 8765
  # the RefBox bridge on the laptop the base stations reach (the match was started with --refbox ... --external refbox)
  arena run refbox --match demo --connect tcp/192.168.1.10:7447"""


def add_parser(sub) -> None:
    r = add_command(sub, "run", "start one process of a match on its own (hardware-in-the-loop)", EXAMPLES)
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
    r.add_argument(
        "--policy",
        metavar="FILE",
        help="robot, basestation: this computer's copy of the policy file the team plays (its strategy is "
        "policy:PATH, a path on the computer that started the match; docs/learning.md)",
    )
    allow_pickle_flag(r)
    r.add_argument("--mode", choices=["peer", "client"], default="peer", help="zenoh mode (peer)")
    r.add_argument(
        "--credentials",
        metavar="FILE",
        help="this process's credentials file from arena match or arena credentials (a zenoh config fragment: "
        "user, password, TLS root, MAC key); every match that made one for it needs it. router: make the match "
        "secure with the credentials directory DIR (provisioned once: kept, what is missing made)",
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
    add_match_flags(eng, required=False, seed=False)


def run(args: argparse.Namespace) -> int:
    from arena.match.run import Job, start

    job = Job(
        kind=args.kind,
        match=args.match,
        connect=(args.connect,) if args.connect else (),
        listen=(args.listen,) if args.listen else (),
        mode=args.mode,
        team=args.team,
        robot=args.robot,
        seed=args.seed,
        realtime=args.realtime,
        config=args.config,
        policy=args.policy,
        credentials=args.credentials,
        startup_timeout=args.startup_timeout,
        log_level=args.log_level,
        record=args.record,
        host=args.host,
        port=args.port,
    )
    cfg = None
    if args.kind == "engine" and not args.config:
        try:  # the engine only needs to know that the match records; the path is the recorder's
            cfg = match_config(args, realtime=args.realtime, tap=bool(args.record))
        except (ConfigError, ValueError) as exc:
            print(f"arena run: error: {exc}", file=sys.stderr)
            return 2
    from arena.runtime.session import OPENED

    before, OPENED[0] = OPENED[0], False
    code = start(job, cfg)
    opened, OPENED[0] = OPENED[0], before or OPENED[0]
    if code == 2 and opened:
        # Refused after a zenoh session was open (a second identity, a wrong match): its one line is
        # said. Leave now: at the interpreter's teardown zenoh's runtime threads can still panic
        # ("AccessError"), and their backtrace would stand after that line.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code
