"""`arena match`'s MSL RefBox flags (docs/refbox.md) and their `RefboxParams`."""

from __future__ import annotations

import argparse

from arena.config import ConfigError


def add_refbox_flags(m: argparse.ArgumentParser) -> None:
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


def warn_unreachable_refbox(endpoint: str) -> None:
    """Said before the match starts, not only in its report: the referee keeps trying while it plays."""
    import sys

    from arena.refbox.client import unreachable
    from arena.rules import refbox_protocol as rp

    host, port = rp.parse_endpoint(endpoint)
    if why := unreachable(host, port):
        print(
            f"arena match: warning: --refbox-follow {endpoint}: cannot connect ({why}); the match starts and the "
            "referee keeps trying, but until the RefBox answers nobody restarts play (never connected: the match is void)",
            file=sys.stderr,
        )


def refbox_params(args: argparse.Namespace):
    """The RefBox flags of `arena match` as `RefboxParams` (None without any); bad values are a ConfigError."""
    flags = ("refbox", "refbox_teams", "refbox_protocol", "refbox_swap", "refbox_targets", "refbox_wait")
    if not any(getattr(args, f) for f in (*flags, "refbox_follow", "via_refbox")):
        return None  # none given: the protocol module (~2 ms of imports) is not needed
    from pathlib import Path

    from arena.config import RefboxParams
    from arena.rules import refbox_protocol as rp

    changes: dict[str, object] = {}
    try:
        if args.refbox:
            from arena.refbox.server import check_listen

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
