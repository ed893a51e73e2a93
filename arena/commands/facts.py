"""`arena facts`: play matches in process and measure them, per match and per strategy."""

from __future__ import annotations

import argparse

from arena.commands._common import add_command
from arena.commands._match_flags import add_match_flags, match_config
from arena.config import ConfigError

CATCH_SIGTERM = True
STOPS_PROCESSES = "every match still playing was stopped, its worker with it"  # several matches, not one

EXAMPLES = """examples:
  arena facts --seeds 20                             # 20 chase-and-shoot matches, 2 x 60 s, in process
  arena facts --seeds 10 --home AD --away BS         # shots, saves, blocks, stuck robots, fouls per team
  arena facts --round-robin AD,AS,BD,BS --legs 4 --half-time 120   # the paper's Table 2 and Fig. 9 ratio
  arena facts --seeds 10 --home AD --away BS --perception-latency 0  # robots that see the present
  arena facts --seeds 10 --home AD --away BS --json  # every match's facts and the totals per strategy, as JSON
  arena facts --seeds 10 --config match.toml         # every match with the file's field, rules, timing, links"""


def add_parser(sub) -> None:
    fa = add_command(
        sub,
        "facts",
        "play matches in process and measure them: rules and team-play facts per match and strategy",
        EXAMPLES,
    )
    fa.add_argument("--seeds", type=int, default=20, metavar="N", help="matches, seeds first-seed.. (20)")
    fa.add_argument("--first-seed", type=int, default=0, metavar="S", help="first seed (0)")
    # The match every seed plays: arena match's flags, with facts' own defaults; --seed is the round robin's.
    add_match_flags(fa, seed=False, config=True, defaults={"half_time": 60.0, "home": "chase", "away": "chase"})
    fa.add_argument("--workers", type=int, default=0, metavar="N", help="matches at once; 0 (the default): up to 2")
    fa.add_argument("--round-robin", metavar="A,B,...", help="instead: every pairing of these strategies --legs times")
    fa.add_argument("--legs", type=int, default=4, metavar="N", help="round robin: matches per pairing (4)")
    fa.add_argument("--seed", type=int, default=0, metavar="N", help="round robin: the tournament seed (0)")
    fa.add_argument("--json", action="store_true", help="print one JSON object instead of tables")


def run(args: argparse.Namespace) -> int:
    from arena.experiments import facts

    if args.round_robin is not None and len({s.strip() for s in args.round_robin.split(",") if s.strip()}) < 2:
        raise ConfigError(f"--round-robin {args.round_robin}: needs at least two different strategies")
    every = match_config(args, seed=False)  # --seed is the round robin's
    return facts.main(
        every,
        seeds=args.seeds,
        first_seed=args.first_seed,
        workers=args.workers or None,
        round_robin_of=[s for s in (args.round_robin or "").split(",") if s] or None,
        legs=args.legs,
        seed=args.seed,
        as_json=args.json,
    )
