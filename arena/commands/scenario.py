"""`arena scenario run FILE|DIR`: every scenario at N seeds, a verdict each, a pass rate with its interval.

The parser is built here and the work is `arena.scenarios` (scenarios/runner.py);
nothing in the library imports this module.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from pathlib import Path

from arena.commands._match_flags import allow_pickle_flag

EXAMPLES = """\
examples:
  arena scenario run corner.scenario.toml                      # each scenario once, seed 0
  arena scenario run tests/scenarios/ --seeds 10 --jobs 2      # every *.scenario.toml below, 10 seeds each
  arena scenario run "$(arena scenario library)" --seeds 3 --junit report.xml   # the shipped library
  arena scenario run corner.scenario.toml --name corner-attack --seed 4 --record run.mcap   # replay one run
  arena scenario run corner.scenario.toml --engine processes   # every process its own OS process
  arena scenario run "$(arena scenario library)/behaviour/corner-routine.scenario.toml" --seeds 100 --jobs 2
                                                               # a pass rate over randomised starts

A run fails when an expectation fails; a scenario fails when its pass rate over the
seeds is below its min_pass. On a terminal each run says when it is done; a last line
counts the scenarios passed and failed. A failed scenario's failed runs are written as
MCAP files (--records, default scenario-runs/) for arena review, and each failure
prints the command that replays its run, from any directory. Ctrl-C stops: the runs
already done are reported. Exit 0: every scenario passed; 1: one failed; 2: a bad file
or flag; 130: interrupted. docs/scenarios.md has the file format."""


CATCH_SIGTERM = True  # SIGTERM stops as Ctrl-C does: the runs done are reported (arena/cli.py)


def add_parser(sub) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "scenario",
        help="run scenario files: verdicts per seed, pass rates (docs/scenarios.md)",
        description="Run scenario files (docs/scenarios.md), or print where the shipped library is.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "action",
        choices=("run", "library"),
        metavar="{run,library}",  # named so in "the following arguments are required"
        help="run: play and judge; library: print its directory",
    )
    p.add_argument("target", nargs="?", metavar="FILE|DIR", help="a scenario file, or a directory of *.scenario.toml")
    seeds = p.add_mutually_exclusive_group()
    seeds.add_argument("--seeds", type=_count, default=1, metavar="N", help="seeds 0..N-1 per scenario (1)")
    seeds.add_argument("--seed", type=_seed, metavar="S", help="just this seed")
    p.add_argument("--name", metavar="NAME", help="just the scenario called NAME")
    p.add_argument("--engine", choices=("inprocess", "processes"), default="inprocess", help="(inprocess)")
    p.add_argument("--jobs", type=_count, default=1, metavar="J", help="runs at a time (1)")
    p.add_argument("--json", action="store_true", help="one JSON object: every scenario, run and verdict")
    p.add_argument("--junit", metavar="FILE", help="write a JUnit XML report, one test case per scenario")
    p.add_argument("--record", metavar="PATH", help="with one scenario and one seed: write the run's MCAP here")
    allow_pickle_flag(p)
    p.add_argument(
        "--records", metavar="DIR", default="scenario-runs", help="MCAP files of failed runs (scenario-runs)"
    )
    return p


def _count(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number 1..100000, got {text!r}") from None
    if not 1 <= n <= 100_000:
        raise argparse.ArgumentTypeError(f"expected a whole number 1..100000, got {text!r}")
    return n


def _seed(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a seed >= 0, got {text!r}") from None
    if not 0 <= n < 2**63:
        raise argparse.ArgumentTypeError(f"expected a seed in [0, 2^63), got {text!r}")
    return n


def _job(item):
    from arena.scenarios import run_one

    sc, seed, engine, record = item
    return run_one(sc, seed, engine, record)


def chosen(args: argparse.Namespace) -> tuple[list, list[int]]:
    """The scenarios and seeds the flags name; ScenarioError (one line) for a bad file or flag."""
    from arena.scenarios import ScenarioError, discover, load_all

    if not args.target:
        raise ScenarioError("run needs a FILE or DIR")
    scenarios = [sc for path in discover(args.target) for sc in load_all(path)]
    if args.name:
        named = [sc for sc in scenarios if sc.name == args.name]
        if scenarios and not named:
            have = ", ".join(sorted({sc.name for sc in scenarios}))
            raise ScenarioError(f"{args.target}: no scenario named {args.name!r} (it has: {have})")
        scenarios = named
    if not scenarios:
        raise ScenarioError(f"{args.target}: no *.scenario.toml files")
    external = [sc for sc in scenarios if sc.spec.play.external]
    if external and args.engine != "processes":
        raise ScenarioError(
            f"{external[0].path}: {external[0].name!r} has external processes (play.external): "
            "run it with --engine processes"
        )
    seeds = [args.seed] if args.seed is not None else list(range(args.seeds))
    if args.record and (len(scenarios) != 1 or len(seeds) != 1):
        raise ScenarioError("--record needs one scenario (--name) and one seed (--seed)")
    if args.record:  # as arena match --record: a new file, never an existing recording overwritten
        from arena.config import ConfigError
        from arena.match.run import record_path

        try:
            Path(args.record).expanduser().parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ScenarioError(f"--record {args.record}: cannot make its directory ({exc.strerror or exc})") from None
        try:
            args.record = record_path(args.record, fresh=True)
        except ConfigError as exc:
            raise ScenarioError(str(exc)) from None
    if args.junit:  # checked now, not after every run has played
        junit = Path(args.junit).expanduser()
        if not junit.parent.resolve().is_dir() or junit.is_dir():
            raise ScenarioError(
                f"--junit {args.junit}: {'is a directory' if junit.is_dir() else 'its directory does not exist'}"
            )
    return scenarios, seeds


def run(args: argparse.Namespace) -> int:
    from arena.scenarios import Outcome, ScenarioError
    from arena.scenarios.junit import write_junit
    from arena.scenarios.library import LIBRARY

    if args.action == "library":
        if args.target:
            print(f"arena scenario: error: library takes no FILE|DIR, got {args.target!r}", file=sys.stderr)
            return 2
        print(LIBRARY)
        return 0
    try:
        scenarios, seeds = chosen(args)
    except ScenarioError as exc:
        print(f"arena scenario: error: {exc}", file=sys.stderr)
        return 2
    for sc in scenarios:
        for note in sc.notes:
            print(f"arena scenario: note: {sc.path}: {note}", file=sys.stderr)
    items = [(sc, s, args.engine, args.record or "") for sc in scenarios for s in seeds]
    t0 = time.monotonic()
    verdicts, stop = play_all(items, args.jobs, progress(len(items)))
    outcomes = [
        Outcome(sc, sorted((v for v in verdicts if v.scenario == sc.name and v.path == sc.path), key=lambda v: v.seed))
        for sc in scenarios
    ]
    outcomes = [o for o in outcomes if o.verdicts]  # interrupted: the scenarios with a finished run
    for o in outcomes:
        if not o.passed and not args.record and stop is None:
            record_failures(o, args.records)
    if args.junit:
        write_junit(args.junit, outcomes)
    summary = closing(outcomes, time.monotonic() - t0, len(verdicts), len(items))
    if args.json:
        out = {"passed": all(o.passed for o in outcomes) and stop is None, "summary": summary}
        print(json.dumps(out | {"scenarios": [o.to_json() for o in outcomes]}))
    else:
        for o in outcomes:
            print(o.describe(args.records))
        print(summary, flush=True)
    if stop is not None:
        raise stop  # the CLI says "interrupted" and exits 130 (143 for SIGTERM)
    return 0 if all(o.passed for o in outcomes) else 1


def play_all(items: list, jobs: int, done) -> tuple[list, KeyboardInterrupt | None]:
    """Every run, `done(verdict)` as each ends; Ctrl-C (or SIGTERM) stops and returns the runs finished."""
    from arena.experiments import pools

    verdicts: list = []
    try:
        if jobs > 1 and len(items) > 1:
            pool, stopped = ProcessPoolExecutor(min(jobs, len(items)), mp_context=get_context("fork")), True
            try:
                for future in as_completed([pool.submit(_job, item) for item in items]):
                    verdicts.append(future.result())
                    done(verdicts[-1])
                stopped = False
            finally:
                pools.stop(pool, now=stopped)
        else:
            for item in items:
                verdicts.append(_job(item))
                done(verdicts[-1])
    except KeyboardInterrupt as exc:
        return verdicts, exc
    return verdicts, None


def progress(total: int):
    """On a terminal, one line on stderr per run as it ends; piped, nothing (the verdicts follow)."""
    count = [0]

    def done(v) -> None:
        count[0] += 1
        if sys.stderr.isatty():
            drawn = f" ({v.drawn_text()})" if v.drawn else ""
            word = "pass" if v.passed else "FAIL"
            print(f"[{count[0]}/{total}] {word} {v.scenario} seed {v.seed}{drawn}, {v.seconds:.1f} s", file=sys.stderr)

    return done


def closing(outcomes: list, seconds: float, finished: int, total: int) -> str:
    """The last line: scenarios passed and failed, the time, and what an interruption left out."""
    passed = sum(o.passed for o in outcomes)
    line = f"{passed} passed, {len(outcomes) - passed} failed in {seconds:.0f} s ({finished} runs)"
    return line if finished == total else f"{line}; interrupted: {total - finished} of {total} runs not played"


def record_failures(o, directory: str, most: int = 3) -> None:
    """Play a failed scenario's first failed runs again, recorded: the same runs, now as MCAP files."""
    import dataclasses

    from arena.scenarios import run_one

    os.makedirs(directory, exist_ok=True)
    for i, v in enumerate(o.verdicts):
        if v.passed or most <= 0:
            continue
        most -= 1
        path = v.record_name(directory)
        if os.path.exists(path):  # an earlier run's file: this run's recording replaces it
            os.unlink(path)
        again = run_one(o.scenario, v.seed, v.engine, path)
        o.verdicts[i] = dataclasses.replace(v, record=path if again.digest == v.digest else "")
