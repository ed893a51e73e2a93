"""`arena bench WHAT`: benchmarks that print throughput and ratios (medians of several runs)."""

from __future__ import annotations

import argparse

from arena.commands._common import add_command, positive_int
from arena.commands._match_flags import add_match_flags, match_config
from arena.config import ConfigError

CATCH_SIGTERM = True
STOPS_PROCESSES = True

EXAMPLES = """examples:
  arena bench match                # median rtf of 3 lockstep 2x60 s 3v3 matches
  arena bench match --runs 5 --half-time 120 --link wifi
  arena bench record               # median rtf with and without --record, and the ratio
  arena bench robot                # median us per robot control step and per F-SFM step
  arena bench throughput --runs 5  # both engines interleaved: rtf, ratio, start-up, tournament matches/hour
  arena bench throughput --rsoccer ~/rsoccer/bin/python  # and rSoccer's VSS-v0 beside our match
  arena bench learn --half-time 30 # env steps/cpu-s for 1 and 3 learners vs. the match; vector env 2 vs. 1
  arena bench experiment          # CPU the experiment runner adds to the in-process matches it plays
  arena bench scenario --runs 10   # 10-s scenario runs per minute, in process, and the ratio to a plain match
  arena bench refbox               # RefBox bridge parsing of hostile messages: us per kB at 100 kB and 1 MB
  arena bench nav                  # paper 1 Tables 4-6 and paper 3's SAROG/GNRON, 10 trials per scheme
  arena bench nav --trials 3 --only static,SAROG --plots navplots/
  arena bench nav --scenarios my_scenarios.toml --json   # your own scenarios (see experiments/navbench/navbench.toml)"""


# The match flags (arena match's, `add_match_flags`; None or [] when not given) and bench's own defaults.
MATCH = ("config_file", "half_time", "robots", "link", "link_param", "perception_latency", "batch")
MATCH_DEFAULTS = {"half_time": 60.0}
# The flags each benchmark reads (besides --json); any other one given is refused, not ignored.
USES = {
    "match": {"runs", *MATCH},
    "record": {"runs", *MATCH},
    "throughput": {"runs", *MATCH, "strategy", "rsoccer"},
    "robot": {"strategy"},
    "learn": {"runs", "half_time", "strategy"},
    "scenario": {"runs"},
    "refbox": {"runs"},
    "experiment": {"runs", *MATCH, "strategy"},
    "nav": {"trials", "seed", "scenarios", "only", "plots"},
}
DEFAULTS = {
    "strategy": "advance-dynamic",
    "runs": 3,
    **{k: [] if k == "link_param" else None for k in MATCH},
    "trials": 10,
    "seed": 0,
    "scenarios": None,
    "only": None,
    "plots": None,
    "rsoccer": None,
}


def add_parser(sub) -> None:
    b = add_command(sub, "bench", "benchmarks: print throughput and ratios (medians of several runs)", EXAMPLES)
    b.add_argument(
        "what",
        choices=["match", "record", "robot", "nav", "throughput", "learn", "scenario", "refbox", "experiment"],
        help="match: speed; record: the cost of --record; robot: us per robot control step and F-SFM step; "
        "nav: the navigators in their papers' scenarios; throughput: both engines (--engine) interleaved, "
        "side by side; learn: env steps vs. in-process match ticks per CPU-second, and the vector env "
        "on 2 workers vs. 1 (needs the learn extra); scenario: 10-s scenario runs per minute in process, "
        "and the ratio to a plain match of the same length; refbox: the bridge's parsing of hostile messages "
        "(us per kB at 100 kB and 1 MB); experiment: the CPU the experiment runner adds to "
        "the in-process matches it plays, side by side with a bare loop",
    )
    b.add_argument(
        "--strategy",
        default=DEFAULTS["strategy"],
        metavar="NAME",
        help="robot, throughput, learn: strategy (both teams); experiment: team a's, against BS (AD)",
    )
    b.add_argument("--runs", type=positive_int, default=DEFAULTS["runs"], metavar="N", help="runs (3)")
    # match, record, throughput: the match they play (learn: --half-time only)
    add_match_flags(b, seed=False, teams=False, config=True, defaults=MATCH_DEFAULTS)
    b.add_argument("--json", action="store_true")
    b.add_argument(
        "--trials",
        type=positive_int,
        default=DEFAULTS["trials"],
        metavar="N",
        help="nav: trials per scheme and scenario (10)",
    )
    b.add_argument("--seed", type=int, default=DEFAULTS["seed"], metavar="N", help="nav: seed of the trials' noise (0)")
    b.add_argument(
        "--scenarios",
        metavar="FILE",
        help="nav: scenario file (default: the built-in experiments/navbench/navbench.toml)",
    )
    b.add_argument("--only", action="append", metavar="NAME[,NAME]", help="nav: run only these scenarios")
    b.add_argument("--plots", metavar="DIR", help="nav: also write PNG trajectory plots into DIR")
    b.add_argument(
        "--rsoccer",
        metavar="PYTHON",
        help="throughput: a Python 3.10 with rSoccer (rsoccer-gym, rc-robosim) installed: its VSS-v0 beside our match",
    )


def run(args: argparse.Namespace) -> int:
    from arena.experiments import bench
    from arena.strategies import registry

    unused = [k for k, v in DEFAULTS.items() if k not in USES[args.what] and getattr(args, k) != v]
    if unused:  # learn and scenario played 3v3 on ideal links whatever --robots and --link said
        flag = "--" + unused[0].replace("_", "-")
        takes = ", ".join("--" + k.replace("_", "-") for k in DEFAULTS if k in USES[args.what])
        raise ConfigError(f"{flag} does not apply to arena bench {args.what} (it takes {takes} and --json)")
    if args.what in ("match", "record", "throughput", "experiment"):  # checked before the first run says it starts
        base = match_config(args, seed=False)  # --seed is nav's
        if args.what == "throughput":  # its matches are processes of their own: a bad name would fail in each
            strategy = registry.resolve_name(args.strategy)
    if args.what == "record":
        return bench.bench_record(base, args.runs, args.json)
    if args.what == "robot":
        return bench.bench_robot(args.strategy, args.json)
    if args.what == "learn":
        registry.resolve_name(args.strategy)
        try:
            from arena.learn.bench import bench_learn
        except ImportError as exc:
            raise ConfigError(str(exc)) from None
        return bench_learn(args.runs, args.half_time or MATCH_DEFAULTS["half_time"], args.strategy, args.json)
    if args.what == "experiment":
        from arena.experiments.experiment_bench import bench_experiment

        name = registry.resolve_name(args.strategy)
        return bench_experiment(base.replace(home=name, away="basic-static"), args.runs, args.json)
    if args.what == "scenario":
        from arena.scenarios.bench import bench_scenario

        return bench_scenario(args.runs, args.json)
    if args.what == "refbox":
        from arena.refbox.bench import bench_refbox

        return bench_refbox(args.runs, args.json)
    if args.what == "throughput":
        from arena.experiments import throughput

        try:  # the learning env's row, with the learn extra
            from arena.learn.bench import learn_rates
        except ImportError:
            learn_rates = None  # type: ignore[assignment]
        return throughput.bench_throughput(base, args.runs, strategy, args.json, learn_rates, args.rsoccer or "")
    if args.what == "nav":
        from arena.experiments import navbench

        return navbench.main(
            scenarios=args.scenarios,
            only=args.only or (),
            trials=args.trials,
            seed=args.seed,
            plots=args.plots,
            as_json=args.json,
        )
    return bench.bench_match(base, args.runs, args.json)
