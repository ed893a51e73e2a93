"""`arena operator`: put teleports and referee overrides into a live session, as the `operator` principal."""

from __future__ import annotations

import argparse
import sys
import time

from arena.commands._common import add_command, seconds

EXAMPLES = """examples:
  # a live session: arena match --home BS --away AD --realtime --listen tcp/127.0.0.1:7447 --match demo \\
  #     --credentials creds    (or the operator.json5 path that arena match prints as it starts)
  arena operator --match demo --connect tcp/127.0.0.1:7447 --credentials creds/operator.json5 \\
      '{"type": "teleport_ball", "x": 3.0, "y": 1.0, "vx": 0, "vy": 0}'
  arena operator --match demo --connect tcp/127.0.0.1:7447 --credentials creds/operator.json5 \\
      '{"type": "referee", "command": "CORNER", "team": "a"}'
  arena operator --match demo --connect tcp/127.0.0.1:7447 --credentials creds/operator.json5 \\
      '{"type": "teleport_robot", "team": "b", "robot": 1, "x": -2.0, "y": 0.5, "orientation": 3.14}'
  # a secure match: the same file, through the router's TLS port
  arena operator --match demo --connect tls/192.168.1.10:7447 --credentials creds/operator.json5 '{...}'

Each ACTION is one JSON map of schemas/README.md: TeleportBall ("type": "teleport_ball"),
TeleportRobot ("teleport_robot") or RefereeOverride ("referee"). The engine and the referee
of a live session (--realtime, or --live) apply them at their next tick and list them in
their summaries' `operator`; a lockstep match without --live does not listen. A frame carries
the operator's MAC (the key in operator.json5): without it, the match's engine and referee count
it as forged and apply nothing; an action out of range (not finite, beyond the fence, faster than
the robot model) is refused and counted."""


def add_parser(sub) -> None:
    p = add_command(
        sub, "operator", "teleport the ball or robots, or force a referee command, in a live session", EXAMPLES
    )
    p.add_argument("actions", nargs="+", metavar="ACTION", help="a JSON map: teleport_ball, teleport_robot or referee")
    p.add_argument("--match", required=True, metavar="ID", help="match id (its key prefix arena/<ID>/)")
    p.add_argument("--connect", required=True, metavar="ENDPOINT", help="the match's router, e.g. tcp/10.0.0.5:7447")
    p.add_argument(
        "--credentials",
        metavar="FILE",
        help="operator.json5: its key signs the frame (the engine and the referee drop one without it). "
        "arena match prints where it is for a live session, or writes it in --credentials DIR",
    )
    p.add_argument("--mode", choices=["peer", "client"], default="client", help="zenoh mode (client)")
    p.add_argument(
        "--wait", type=seconds, default=10.0, metavar="S", help="wait this long [s] for the engine to listen (10)"
    )


def parse_actions(texts: list[str]) -> list:
    """The actions as messages; ValueError naming the bad one."""
    import msgspec

    from arena.schemas.messages import RefereeOverride, TeleportBall, TeleportRobot

    kinds = (TeleportBall, TeleportRobot, RefereeOverride)
    types = ", ".join(k.__struct_config__.tag for k in kinds)
    out = []
    for i, text in enumerate(texts, 1):
        try:
            out.append(msgspec.json.decode(text, type=TeleportBall | TeleportRobot | RefereeOverride))
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            why = str(exc)
            if why.endswith("- at `$.type`") or why == "Object missing required field `type`":
                why += f" (the types: {types})"
            raise ValueError(f"ACTION {i}: {why}") from None
    return out


def _open(net, credentials: str | None):
    """The session; a router that listens but refuses it is ConfigError with the cause, as `arena run` says it."""
    from arena.match.run import refusal, refused_by
    from arena.runtime.session import EndpointError, open_session
    from arena.schemas.keys import OPERATOR_PRINCIPAL

    try:
        return open_session(net)
    except EndpointError:
        ep = refused_by(net.connect)
        if ep is None:
            raise
        raise refusal(ep, net, credentials, OPERATOR_PRINCIPAL) from None


def run(args: argparse.Namespace) -> int:
    from arena.config import ConfigError
    from arena.runtime.session import NetConfig
    from arena.schemas.keys import OPERATOR_PRINCIPAL, Keys
    from arena.schemas.messages import Operator, encode

    try:
        actions = parse_actions(args.actions)
        base, mode, sign = "", args.mode, None
        if args.credentials:
            from arena.match.run import load_credentials

            base, asked, keyring = load_credentials(args.credentials, OPERATOR_PRINCIPAL)
            mode = asked or mode
            sign = keyring.signer(Keys(args.match).operator())
        net = NetConfig(mode=mode, connect=(args.connect,), base=base)
    except (ValueError, ConfigError) as exc:
        print(f"arena operator: error: {exc}", file=sys.stderr)
        return 2
    key = Keys(args.match).operator()
    with _open(net, args.credentials) as session:
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
        payload = encode(Operator(seq=time.time_ns() // 1000, actions=actions))
        pub.put(payload, attachment=None if sign is None else sign(payload))  # the operator's MAC (runtime/mac.py)
        pub.undeclare()
    print(f"sent {len(actions)} action(s) to {key}")
    return 0
