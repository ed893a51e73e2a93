"""`arena credentials init|rotate|show DIR`: a credentials directory, provisioned once."""

from __future__ import annotations

import argparse
from pathlib import Path

from arena.commands._common import add_command
from arena.config import ConfigError

EXAMPLES = """examples:
  arena credentials init creds/                  # every principal of a match with up to 6 robots a team
  scp creds/robot-a-1.json5 robot-a-1:          # once: it works in every match that uses creds/
  arena match --home BS --away BS --listen tcp/0.0.0.0:7447 --external a/1 --credentials creds/
  arena credentials show creds/                  # the set, the certificate's expiry, each file's owner
  arena credentials rotate creds/ a/1            # robot a/1's computer was lost: copy its new file
  arena credentials rotate creds/                # everything new, CA included: copy every file again"""


def add_parser(sub) -> argparse.ArgumentParser:
    text = "make, replace or list a credentials directory that every match can use (provisioned once)"
    p = add_command(sub, "credentials", text, EXAMPLES)
    p.add_argument(
        "action",
        choices=["init", "rotate", "show"],
        metavar="{init,rotate,show}",  # named so in "the following arguments are required"
        help="init: create what is missing; "
        "rotate: new secrets (for the PRINCIPALs given, else for all); show: list the set",
    )
    p.add_argument("directory", metavar="DIR", help="the credentials directory (made mode 0700)")
    p.add_argument(  # a default, or argparse lists it among the required arguments
        "principals",
        nargs="*",
        default=[],
        metavar="PRINCIPAL",
        help="rotate: e.g. a/1 or robot/a/1, basestation/b, operator (default: all)",
    )
    p.add_argument("--robots", type=int, default=6, metavar="N", help="init: robots per team to provision (6)")
    return p


def run(args: argparse.Namespace) -> int:
    from arena.runtime.acl import COLLECTOR_PRINCIPAL
    from arena.runtime.provision import provision, rotate, show
    from arena.schemas.keys import process_names

    directory = Path(args.directory)
    if args.principals and args.action != "rotate":
        raise ConfigError(f"PRINCIPAL applies to rotate only, not to {args.action}")
    if args.action == "init":
        if not 1 <= args.robots <= 6:
            raise ConfigError("--robots must be between 1 and 6")
        _, made = provision(directory, [*process_names(args.robots), "refbox", COLLECTOR_PRINCIPAL], args.robots)
        print(f"{directory}: {'made ' + ', '.join(made) if made else 'complete already, nothing changed'}")
    elif args.action == "rotate":
        made = rotate(directory, [_principal(p) for p in args.principals])
        away = [m for m in made if m.startswith(("robot-", "basestation-"))]  # what may run on another computer
        print(
            f"{directory}: new {', '.join(made)}; copy {', '.join(away) or 'none of them'} again to the computer each is on"
        )
    if args.action in ("init", "show"):
        print("\n".join(show(directory)))
    return 0


def _principal(name: str) -> str:
    """`a/1` as `robot/a/1`, the short form `--external` takes; a principal that is no process
    (`operator`, `collector`) as given."""
    from arena.config import ProcessId

    try:
        return str(ProcessId.parse(name))
    except ConfigError:
        return name
