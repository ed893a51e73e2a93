"""`arena experiment`: sweeps over any match setting (`run FILE`), "is my change better?"
(`compare`, paired matches and a sequential test; docs/experiments.md) and the search of a
strategy's parameters (`tune`, arena/commands/_tune.py; docs/strategies.md, "Tuning")."""

from __future__ import annotations

import argparse
import json
import sys

from arena.commands._common import add_command, ray_flag
from arena.commands._match_flags import add_match_flags
from arena.commands._tune import add_tune_parser, run_tune
from arena.config import ConfigError

EXAMPLES = """examples:
  arena experiment run examples/studies/wifi-latency.toml --out runs/wifi   # every cell, seed and end
  arena experiment run sweep.toml --jobs 2 --out runs/sweep --resume        # continue after Ctrl-C or a crash
  arena experiment run sweep.toml --ray --out runs/sweep                    # every match a task on a local Ray
  arena experiment run sweep.toml --ray auto --json                         # join this node's Ray cluster
  arena experiment compare --candidate AD --baseline BS --half-time 30 --elo1 50   # SPRT: is AD better?
  arena experiment compare --candidate AD --baseline AS --opponents BD,BS --elo0 0 --elo1 10 --max-pairs 200
  arena experiment tune --strategy AD --opponents AS,BS --params kick_speed,keeper_gain --out runs/tune-ad
(docs/experiments.md: the experiment file key by key, and what compare prints)"""

RUN_EXAMPLES = """examples:
  arena experiment run sweep.toml --out runs/sweep            # rows.csv, summary.json, plots/, report.md there
  arena experiment run sweep.toml --out runs/sweep --resume   # only the matches not yet in runs/sweep
  arena experiment run sweep.toml --jobs 1                    # every match in this process, one after another
  arena experiment run sweep.toml --ray 10.0.0.5:6379         # the Ray cluster whose head node is there
  arena experiment run examples/studies/corner-latency.toml   # base: a scenario file; pass rates per cell"""

COMPARE_EXAMPLES = """examples:
  arena experiment compare --candidate AD --baseline BS --half-time 30
  arena experiment compare --candidate my-team --baseline BS --opponents AD,AS,BD --max-pairs 400 --jobs 2
  arena experiment compare --candidate AD --baseline AS --elo0 -5 --elo1 5 --config match.toml --json
exit code: 0 the candidate is better (H1 accepted), 1 it is not (H0 accepted), 3 undecided at --max-pairs,
2 bad input"""

CATCH_SIGTERM = True
STOPS_PROCESSES = True


def add_parser(sub) -> None:
    ex = add_command(sub, "experiment", "sweeps over any match setting, paired tests of a change, tuning", EXAMPLES)
    what = ex.add_subparsers(dest="experiment", required=True, metavar="{run,compare,tune}")
    r = add_command(
        what, "run", "play an experiment file: every cell, seed and end; rows, intervals, plots", RUN_EXAMPLES
    )
    r.add_argument("file", metavar="FILE.toml", help="the experiment file (docs/experiments.md)")
    r.add_argument("--jobs", type=int, default=0, metavar="N", help="matches at once; 0 (the default): one per core")
    ray_flag(r)
    r.add_argument("--out", default=None, metavar="DIR", help="results directory (default: the file's name)")
    r.add_argument("--resume", action="store_true", help="play only the matches not yet in --out")
    r.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    c = add_command(
        what, "compare", "is the candidate better than the baseline? paired matches, SPRT", COMPARE_EXAMPLES
    )
    c.add_argument("--candidate", required=True, metavar="STRATEGY", help="the strategy under test")
    c.add_argument("--baseline", required=True, metavar="STRATEGY", help="the strategy it should beat")
    c.add_argument(
        "--opponents",
        default="",
        metavar="A,B,...",
        help="both play these, the same seeds and ends, and each pair scores the candidate's result against the "
        "baseline's (default: none, the candidate plays the baseline itself)",
    )
    c.add_argument("--elo0", type=float, default=0.0, metavar="ELO", help="H0: normalised Elo at most this (0)")
    c.add_argument("--elo1", type=float, default=2.0, metavar="ELO", help="H1: normalised Elo at least this (2)")
    c.add_argument("--alpha", type=float, default=0.05, metavar="P", help="false positive rate (0.05)")
    c.add_argument("--beta", type=float, default=0.05, metavar="P", help="false negative rate (0.05)")
    c.add_argument("--max-pairs", type=int, default=200, metavar="N", help="stop undecided after N pairs (200)")
    c.add_argument("--first-seed", type=int, default=0, metavar="S", help="pairs play seeds S, S+1, ... (0)")
    add_match_flags(c, seed=False, teams=False, config=True)  # every match's: --config, --half-time, links, ...
    c.add_argument("--jobs", type=int, default=0, metavar="N", help="matches at once; 0 (the default): one per core")
    ray_flag(c)
    c.add_argument("--json", action="store_true", help="print the result as one JSON object")
    add_tune_parser(what)


def run(args: argparse.Namespace) -> int:
    if args.experiment == "tune":
        return run_tune(args)
    if args.jobs < 0:
        raise ConfigError(f"--jobs must be 0 (one per core) or more, got {args.jobs}")
    if args.ray is not None:
        from arena.experiments.cluster import parse_address

        parse_address(args.ray)
    if args.experiment == "compare":
        return _compare(args)
    return _run(args)


def _run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from arena.experiments import design, experiment
    from arena.scenarios.experiment import base as scenario_base

    exp = design.load(args.file, scenarios=scenario_base)  # base may be a scenario file
    source = Path(args.file).read_text()
    out = Path(args.out or Path(args.file).name.removesuffix(".toml"))
    opts = experiment.RunOptions(jobs=args.jobs, ray=args.ray, out=out, resume=args.resume)
    summary, interrupted = experiment.run(exp, opts, source)
    if args.json:
        print(json.dumps(summary, indent=1))
    else:
        print(f"{summary['matches']} matches ({summary['failed']} failed) in {summary['wall_s']:.0f} s: {out}/")
        print(f"  rows: {out}/rows.csv, summary: {out}/summary.json, report: {out}/report.md")
    if interrupted:
        print("arena experiment: interrupted; finished matches are kept (continue with --resume)", file=sys.stderr)
        return 130
    return 1 if summary["failed"] else 0


def _compare(args: argparse.Namespace) -> int:
    from arena.commands._match_flags import match_config
    from arena.experiments import compare
    from arena.strategies import registry

    base = match_config(args, seed=False)
    opponents = [registry.resolve_name(o) for o in args.opponents.split(",") if o.strip()]
    opts = compare.CompareOptions(
        candidate=registry.resolve_name(args.candidate),
        baseline=registry.resolve_name(args.baseline),
        opponents=opponents,
        elo0=args.elo0,
        elo1=args.elo1,
        alpha=args.alpha,
        beta=args.beta,
        max_pairs=args.max_pairs,
        first_seed=args.first_seed,
        jobs=args.jobs,
        ray=args.ray,
    )
    result = compare.run(base, opts, progress=True)
    if args.json:
        print(json.dumps(result, indent=1))
    else:
        print(result["line"])
        print(result["verdict"])
    return result["exit"]
