"""`arena operator`: put teleports and referee overrides into a live session, as the `operator` principal."""

from __future__ import annotations

import argparse
import sys
import time

from arena.commands._common import add_command, seconds

EXAMPLES = """examples:
  # a live session: arena match --home BS --away AD --realtime --listen tcp/127.0.0.1:7447 --match demo --no-secure
  arena operator --match demo --connect tcp/127.0.0.1:7447 '{"type": "teleport_ball", "x": 3.0, "y": 1.0, "vx": 0, "vy": 0}'
  arena operator --match demo --connect tcp/127.0.0.1:7447 '{"type": "referee", "command": "CORNER", "team": "a"}'
  arena operator --match demo --connect tcp/127.0.0.1:7447 \\
      '{"type": "teleport_robot", "team": "b", "robot": 1, "x": -2.0, "y": 0.5, "orientation": 3.14}'
  # a secure match: the operator's credentials file that arena match wrote (--credentials DIR)
  arena operator --match demo --connect tls/192.168.1.10:7447 --credentials creds/operator.json5 '{...}'

Each ACTION is one JSON map of schemas/README.md: TeleportBall ("type": "teleport_ball"),
TeleportRobot ("teleport_robot") or RefereeOverride ("referee"). The engine and the referee
of a live session (--realtime, or --live) apply them at their next tick and list them in
their summaries' `operator`; a lockstep match without --live does not listen."""


def add_parser(sub) -> None:
    p = add_command(
        sub, "operator", "teleport the ball or robots, or force a referee command, in a live session", EXAMPLES
    )
    p.add_argument("actions", nargs="+", metavar="ACTION", help="a JSON map: teleport_ball, teleport_robot or referee")
    p.add_argument("--match", required=True, metavar="ID", help="match id (its key prefix arena/<ID>/)")
    p.add_argument("--connect", required=True, metavar="ENDPOINT", help="the match's router, e.g. tcp/10.0.0.5:7447")
    p.add_argument("--credentials", metavar="FILE", help="operator.json5 of a secure match (arena match --credentials)")
    p.add_argument("--mode", choices=["peer", "client"], default="client", help="zenoh mode (client)")
    p.add_argument(
        "--wait", type=seconds, default=10.0, metavar="S", help="wait this long [s] for the engine to listen (10)"
    )


def parse_actions(texts: list[str]) -> list:
    """The actions as messages; ValueError naming the bad one."""
    import msgspec

    from arena.schemas.messages import RefereeOverride, TeleportBall, TeleportRobot

    out = []
    for i, text in enumerate(texts, 1):
        try:
            out.append(msgspec.json.decode(text, type=TeleportBall | TeleportRobot | RefereeOverride))
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            raise ValueError(f"ACTION {i}: {exc}") from None
    return out


def run(args: argparse.Namespace) -> int:
    from arena.runtime.config import ConfigError
    from arena.runtime.session import NetConfig, open_session
    from arena.schemas.keys import OPERATOR_PRINCIPAL, Keys
    from arena.schemas.messages import Operator, encode

    try:
        actions = parse_actions(args.actions)
        base, mode = "", args.mode
        if args.credentials:
            from arena.match.run import load_credentials

            base, asked, _ = load_credentials(args.credentials, OPERATOR_PRINCIPAL)
            mode = asked or mode
        net = NetConfig(mode=mode, connect=(args.connect,), base=base)
    except (ValueError, ConfigError) as exc:
        print(f"arena operator: error: {exc}", file=sys.stderr)
        return 2
    key = Keys(args.match).operator()
    with open_session(net) as session:
        pub = session.declare_publisher(key)
        deadline = time.monotonic() + args.wait
        while not pub.matching_status.matching and time.monotonic() < deadline:
            time.sleep(0.05)
        if not pub.matching_status.matching:
            print(
                f"arena operator: error: nobody listens on {key} within {args.wait:g} s: is match "
                f"{args.match!r} live (--realtime or --live), and may this principal put there?",
                file=sys.stderr,
            )
            return 1
        pub.put(encode(Operator(seq=time.time_ns() // 1000, actions=actions)))
        pub.undeclare()
    print(f"sent {len(actions)} action(s) to {key}")
    return 0
