"""`arena tournament`: a round-robin of strategies, the paper's tables, charts and ratings."""

from __future__ import annotations

import argparse
import json
import sys

from arena.commands._common import ENGINE_FLAG, add_command, positive_int, ray_flag
from arena.commands._match_flags import add_match_flags, allow_pickle_flag, match_config
from arena.config import ConfigError

EXAMPLES = """examples:
  arena tournament                                  # the paper's experiment: 4 strategies x 10 legs = 60 matches
  arena tournament --strategies AD,BS --legs 4 --half-time 60 --out runs/quick
  arena tournament --out runs/paper --resume        # continue after Ctrl-C or a crash
  arena tournament --link congested-wifi --jobs 2 --json
  arena tournament --config match.toml --legs 4     # every match with the file's field, rules, timing, links
  arena tournament --ray                            # every match a task on a local Ray instance (docs/cluster.md)
  arena tournament --ray auto --out runs/big        # join the Ray cluster this node belongs to (ray start ...)
  arena tournament --ray 10.0.0.5:6379 --resume     # join the cluster whose head node is there
  arena tournament --ray auto --ray-runtime-env '{"pip": ["soccer-arena==0.1.0"]}'   # workers install it
  arena tournament --legs 10 --engine inprocess     # one worker process per core, same digests, ~2.5x faster
  arena tournament --param AD.kick_speed=6.0 --param BS.kick_speed=6.0 --out runs/k6   # strategy parameters"""


def add_parser(sub) -> None:
    t = add_command(sub, "tournament", "round-robin of strategies: the paper's tables, charts and ratings", EXAMPLES)
    t.add_argument("--strategies", default="AD,AS,BD,BS", metavar="A,B,...", help="strategies (AD,AS,BD,BS)")
    t.add_argument(
        "--legs", type=positive_int, default=10, metavar="N", help="matches per pairing, home and away alternating (10)"
    )
    add_match_flags(t, seed=False, teams=False, config=True)  # what every match shares
    t.add_argument(
        "--param",
        dest="strategy_param",
        action="append",
        default=[],
        metavar="STRATEGY.NAME=V",
        help="set a strategy's parameter in every match it plays, e.g. AD.kick_speed=7.0 (repeatable; "
        "arena strategies --params AD lists them)",
    )
    t.add_argument("--seed", type=int, default=0, metavar="N", help="tournament seed; match seeds derive from it (0)")
    t.add_argument("--jobs", type=int, default=0, metavar="N", help="matches at once; 0 (the default): one per core")
    t.add_argument("--out", default="tournament", metavar="DIR", help="results directory (tournament)")
    t.add_argument("--resume", action="store_true", help="skip the matches already finished in --out")
    ray_flag(t)
    t.add_argument(
        "--ray-runtime-env",
        metavar="JSON",
        help='with --ray: a Ray runtime_env for the workers, e.g. \'{"pip": ["soccer-arena==0.1.0"]}\'',
    )
    t.add_argument("--json", action="store_true", help="print one JSON object")
    t.add_argument("--engine", **ENGINE_FLAG)
    allow_pickle_flag(t)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from arena.experiments import tournament
    from arena.experiments.tournament_report import print_summary
    from arena.strategies import registry

    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise ConfigError(f"--out {args.out} exists and is not a directory")
    names = [registry.resolve_name(s) for s in args.strategies.split(",") if s.strip()]
    if len(set(names)) < 2:
        raise ConfigError("--strategies needs at least two different strategies")
    base = match_config(args, seed=False)  # what every match shares, each range checked as for arena match
    if args.jobs < 0:
        raise ConfigError(f"--jobs must be 0 (one per core) or more, got {args.jobs}")
    if args.ray is not None:
        from arena.experiments.cluster import parse_address, parse_runtime_env

        parse_address(args.ray)
        parse_runtime_env(args.ray_runtime_env)
    elif args.ray_runtime_env is not None:
        raise ConfigError("--ray-runtime-env needs --ray")
    opts = tournament.TournamentOptions(
        strategies=tuple(names),
        base=base,
        params=strategy_params(args.strategy_param, names),
        legs=args.legs,
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
        print_summary(summary)
    if interrupted:
        print("arena tournament: interrupted; finished matches are kept (continue with --resume)", file=sys.stderr)
        return 130
    return 0


def strategy_params(given: list[str], names: list[str]) -> tuple[tuple[str, str, object], ...]:
    """`--param STRATEGY.NAME=V` as (strategy, name, value), each checked against the strategy's declarations."""
    from arena.strategies import registry
    from arena.strategies.base import check_values

    out = []
    for text in given:
        who, name, value = registry.parse_param(text, teams=())
        strategy = registry.get(who)
        if strategy.name not in names:
            raise ConfigError(
                f"--param {text!r}: {strategy.name} plays no match of this tournament ({', '.join(names)})"
            )
        checked = check_values(strategy.name, strategy.params, {name: value})
        out.append((strategy.name, name, checked[name]))
    return tuple(out)
