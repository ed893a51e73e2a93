"""`arena experiment tune`: its flags and the call of experiments/tune.py (docs/strategies.md, "Tuning")."""

from __future__ import annotations

import argparse
import json
import sys

from arena.commands._common import add_command, positive_int, ray_flag
from arena.commands._match_flags import add_match_flags
from arena.config import ConfigError

TUNE_EXAMPLES = """examples:
  arena experiment tune --strategy AD --opponents AS,BS --params kick_speed,keeper_gain --out runs/tune-ad
  arena experiment tune --strategy AD --opponents AS,BS --params kick_speed,keeper_gain --out runs/tune-ad --resume
  arena experiment tune --strategy AD --opponents BS --iterations 4 --half-time 20 --remeasure 4 --out /tmp/t
  arena experiment tune --strategy AS --opponents AD --params navigator,cruise --method optuna --iterations 40
  arena experiment tune --strategy AD --opponents AS,BD,BS --seeds 2 --c 0.15 --a 0.03 --jobs 2 --json
the result: the best values, and their gain in points per match over the defaults with its 95 % interval,
measured again on fresh seeds (1000000 on) that the search never played"""


def add_tune_parser(what) -> None:
    t = add_command(
        what, "tune", "search a strategy's parameters for the most points against opponents (SPSA)", TUNE_EXAMPLES
    )
    t.add_argument(
        "--strategy",
        required=True,
        metavar="STRATEGY",
        help="the strategy tuned (its parameters: arena strategies --params NAME)",
    )
    t.add_argument(
        "--opponents",
        required=True,
        metavar="A,B,...",
        help="the strategies it plays, each on every seed with both ends",
    )
    t.add_argument(
        "--params",
        default="",
        metavar="NAME,...",
        help="the parameters tuned (default: every number the strategy declares)",
    )
    t.add_argument(
        "--method",
        choices=("spsa", "optuna"),
        default="spsa",
        help="spsa (default), or optuna's TPE (extra [tune]; takes string and bool parameters)",
    )
    t.add_argument(
        "--iterations", type=positive_int, default=20, metavar="N", help="SPSA iterations, or Optuna trials (20)"
    )
    t.add_argument(
        "--seeds",
        type=positive_int,
        default=1,
        metavar="N",
        help="seeds per iteration, each with both ends and every opponent (1)",
    )
    t.add_argument(
        "--remeasure",
        type=positive_int,
        default=10,
        metavar="N",
        help="fresh seeds the best values are measured on against the defaults (10)",
    )
    t.add_argument(
        "--a",
        type=float,
        default=0.02,
        metavar="A",
        help="SPSA step size a: a_k = a / (A + k + 1)^0.602, in units of each range (0.02)",
    )
    t.add_argument(
        "--c",
        type=float,
        default=0.1,
        metavar="C",
        help="SPSA perturbation c: c_k = c / (k + 1)^0.101, in units of each range (0.1)",
    )
    t.add_argument(
        "--A",
        dest="big_a",
        type=float,
        default=None,
        metavar="A",
        help="SPSA stability constant (a tenth of --iterations)",
    )
    t.add_argument(
        "--seed", type=int, default=0, metavar="N", help="the search's seed; tuning matches play seeds N, N+1, ... (0)"
    )
    add_match_flags(t, seed=False, teams=False, config=True)  # every match's: --config, --half-time, links, ...
    t.add_argument("--jobs", type=int, default=0, metavar="N", help="matches at once; 0 (the default): one per core")
    ray_flag(t)
    t.add_argument(
        "--out",
        default="tune",
        metavar="DIR",
        help="results directory: tune.json (the state), history.csv, result.json, trace.png, report.md (tune)",
    )
    t.add_argument("--resume", action="store_true", help="continue the search in --out (the same settings)")
    t.add_argument("--json", action="store_true", help="print the result as one JSON object")


def run_tune(args: argparse.Namespace) -> int:
    from pathlib import Path

    from arena.commands._match_flags import match_config
    from arena.experiments import tune
    from arena.experiments.spsa import Gains, Space
    from arena.strategies import registry

    if args.jobs < 0:
        raise ConfigError(f"--jobs must be 0 (one per core) or more, got {args.jobs}")
    if args.ray is not None:
        from arena.experiments.cluster import parse_address

        parse_address(args.ray)
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise ConfigError(f"--out {args.out} exists and is not a directory")
    strategy = registry.get(args.strategy)
    declared = {p.name: p for p in strategy.params}
    if not declared:
        raise ConfigError(f"--strategy {strategy.name} declares no parameters to tune")
    wanted = [n.strip() for n in args.params.split(",") if n.strip()]
    if not wanted:
        wanted = [p.name for p in strategy.params if p.type in ("int", "float")]
    unknown = [n for n in wanted if n not in declared]
    if unknown or len(set(wanted)) < len(wanted):
        raise ConfigError(
            f"--params {','.join(unknown or wanted)}: {strategy.name}'s parameters are {', '.join(declared)}"
        )
    args.home = args.away = None
    base = match_config(args, seed=False)
    opponents = tuple(registry.resolve_name(o) for o in args.opponents.split(",") if o.strip())
    gains = Gains(a=args.a, c=args.c, A=args.iterations / 10 if args.big_a is None else args.big_a)
    opts = tune.TuneOptions(
        strategy=strategy.name,
        opponents=opponents,
        names=tuple(wanted),
        iterations=args.iterations,
        seeds=args.seeds,
        gains=gains,
        seed=args.seed,
        remeasure=args.remeasure,
        method=args.method,
        jobs=args.jobs,
        ray=args.ray,
        out=Path(args.out),
        resume=args.resume,
        progress=not args.json,
    )
    tune.check(opts, declared)
    try:
        result, interrupted = tune.run(base, opts, Space(tuple(declared[n] for n in wanted)))
    except tune.TuneError as exc:
        print(f"arena experiment tune: {exc}; what was done is kept (continue with --resume)", file=sys.stderr)
        return 1
    if interrupted:
        print(
            "arena experiment tune: interrupted; finished iterations are kept (continue with --resume)", file=sys.stderr
        )
        return 130
    if args.json:
        print(json.dumps(result, indent=1))
        return 0
    rm = result["remeasure"]
    best = ", ".join(f"{k}={v}" for k, v in result["best"].items())
    print(f"best {result['strategy']}: {best}")
    print(
        f"gain {rm['gain']:+.3f} points per match (95 % {rm['ci95'][0]:+.3f} to {rm['ci95'][1]:+.3f}) over the "
        f"defaults, {rm['matches']} matches on fresh seeds {rm['seeds'][0]}-{rm['seeds'][1]} "
        f"(best {rm['best_points']:.2f}, defaults {rm['default_points']:.2f} points per match)"
    )
    print(f"files: {args.out}/report.md, result.json, history.csv, trace.png, tune.json")
    return 0
