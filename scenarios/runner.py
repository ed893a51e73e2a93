"""Running scenarios: one verdict per scenario and seed, a pass rate with its interval.

`run_one` plays a scenario's match (`Scenario.config(seed)`) on either engine
and judges every expectation on what it left (`Trace`): the same verdict and
digest bit for bit on every rerun and on both engines, because the run is the
lockstep match itself. A failing run can be played again with `record`: the
same run, written to an MCAP file that `arena review` reads.

`Outcome` gathers the verdicts of one scenario over N seeds: the pass rate,
its 95 % Wilson score interval, and the scenario's verdict (`min_pass`)."""

from __future__ import annotations

import shlex
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import msgspec

from arena.experiments.ratings import wilson
from arena.scenarios.draws import resolve as resolve_draws
from arena.scenarios.expect import Trace, judge
from arena.scenarios.model import Scenario, run_end
from arena.schemas.messages import EngineEvents, Referee, World

ENGINES = ("inprocess", "processes")


@dataclass(frozen=True)
class Failure:
    name: str
    tick: int
    detail: str


@dataclass(frozen=True)
class Verdict:
    """One scenario at one seed."""

    scenario: str
    path: str
    seed: int
    engine: str
    passed: bool
    failures: tuple[Failure, ...]
    digest: str
    score: tuple[int, int]
    ticks: int
    record: str = ""  # the MCAP of a failed run, if written
    drawn: dict = field(default_factory=dict)  # the numbers drawn for this run (scenarios/draws.py)
    seconds: float = field(default=0.0, compare=False)  # [s] wall time the run took (not part of the verdict)

    def record_name(self, directory: str = "scenario-runs") -> str:
        """Where this run's MCAP goes: one absolute path per file, scenario and seed."""
        stem = Path(self.path).name.split(".")[0]
        return str(Path(directory).expanduser().resolve() / f"{stem}-{self.scenario}-seed{self.seed}.mcap")

    def replay_command(self, directory: str = "scenario-runs") -> str:
        """The command that plays this run again, from any directory. A run already recorded needs no
        --record (its MCAP is `record`); any other is recorded to its own new file."""
        cmd = (
            f"arena scenario run {shlex.quote(str(Path(self.path).resolve()))} --name {shlex.quote(self.scenario)} "
            f"--seed {self.seed} --engine {self.engine}"
        )
        return cmd if self.record else f"{cmd} --record {shlex.quote(self.record_name(directory))}"

    def drawn_text(self) -> str:
        return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in self.drawn.items())

    def to_json(self) -> dict:
        return {
            "scenario": self.scenario,
            "path": self.path,
            "seed": self.seed,
            "engine": self.engine,
            "passed": self.passed,
            "failures": [{"name": f.name, "tick": f.tick, "detail": f.detail} for f in self.failures],
            "digest": self.digest,
            "score": list(self.score),
            "ticks": self.ticks,
            "record": self.record,
            "drawn": self.drawn,
            "seconds": round(self.seconds, 3),
        }


@dataclass
class Outcome:
    """A scenario over its seeds."""

    scenario: Scenario
    verdicts: list[Verdict] = field(default_factory=list)

    @property
    def passed_runs(self) -> int:
        return sum(v.passed for v in self.verdicts)

    @property
    def rate(self) -> float:
        return self.passed_runs / len(self.verdicts) if self.verdicts else 0.0

    @property
    def passed(self) -> bool:
        return bool(self.verdicts) and self.rate >= self.scenario.spec.min_pass

    def describe(self, records: str = "scenario-runs") -> str:
        """The verdict line; for a failed scenario, per failed expectation its name, tick, seed (with the numbers
        drawn for it) and the command that replays the run."""
        n = len(self.verdicts)
        lo, hi = wilson(self.passed_runs, n)
        lines = [
            f"{'PASS' if self.passed else 'FAIL'} {self.scenario.name} ({self.scenario.path}): "
            f"{self.passed_runs}/{n} runs passed, {self.rate:.0%} (95 % CI {lo:.0%}-{hi:.0%}), "
            f"min_pass {self.scenario.spec.min_pass:g}"
        ]
        for v in self.verdicts if not self.passed else ():
            drawn = f" ({v.drawn_text()})" if v.drawn else ""
            for f in v.failures:
                lines.append(f"  seed {v.seed}{drawn}: expectation {f.name!r} failed at tick {f.tick}: {f.detail}")
            if v.failures:
                if v.record:
                    lines.append(f"    recorded: {v.record} (digest {v.digest})")
                lines.append(f"    replay: {v.replay_command(records)}")
        return "\n".join(lines)

    def to_json(self) -> dict:
        lo, hi = wilson(self.passed_runs, len(self.verdicts))
        return {
            "scenario": self.scenario.name,
            "path": self.scenario.path,
            "passed": self.passed,
            "pass_rate": round(self.rate, 4),
            "wilson95": [round(lo, 4), round(hi, 4)],
            "min_pass": self.scenario.spec.min_pass,
            "runs": [v.to_json() for v in self.verdicts],
        }


def _trace(sc: Scenario, worlds: list[World], referees: list[Referee], digests: dict[str, str], events) -> Trace:
    cfg = sc.config()
    f = cfg.field
    commands = [c for r in referees for c in r.commands]
    fence = (f.length / 2 + f.runoff, f.width / 2 + f.runoff)
    scores = [(r.tick, r.score_a, r.score_b) for r in referees]
    return Trace(
        dt=cfg.timing.dt,
        worlds=worlds,
        commands=commands,
        digests=digests,
        fence=fence,
        events=[ev for e in events for ev in e.events],
        scores=scores,
    )


def _play(sc: Scenario, seed: int, engine: str, record: str):
    from arena.match import Processes, play

    # An --external process is started by hand: the launcher says the command to type there.
    announce = lambda text: print(text, file=sys.stderr, flush=True)
    on = Processes(strict=True, announce=announce) if engine == "processes" else engine
    events = "events" if engine == "inprocess" else "engine/events"  # a key here, a recording's topic there
    result = play(sc.config(seed), engine=on, record=record, watch=("world", "referee", events))
    wdec = msgspec.msgpack.Decoder(World).decode
    rdec = msgspec.msgpack.Decoder(Referee).decode
    edec = msgspec.msgpack.Decoder(EngineEvents).decode
    worlds = [wdec(p) for p in result.frames["world"]]
    referees = [rdec(p) for p in result.frames["referee"]]
    evs = [edec(p) for p in result.frames[events]]
    return worlds, referees, dict(result.process_digests), result.digest, evs


def run_one(sc: Scenario, seed: int, engine: str = "inprocess", record: str = "") -> Verdict:
    """Play `sc` at `seed` on `engine` and judge every expectation. `record`: write the MCAP there.

    A scenario with `--external` robots plays on the processes engine only (ValueError otherwise).
    """
    if sc.spec.play.external and engine != "processes":
        raise ValueError(f"{sc.path}: scenario {sc.name!r} has external processes: it needs --engine processes")
    t0 = time.perf_counter()
    worlds, referees, digests, total, events = _play(sc, seed, engine, record)
    trace = _trace(sc, worlds, referees, digests, events)
    failures = []
    end = run_end(resolve_draws(sc.spec, seed)[0], sc.dt)[0]  # time_limit, or the match's end if sooner
    for e in sc.spec.expect:
        ok, tick, detail = judge(e, trace, end)
        if not ok:
            failures.append(Failure(e.name, tick, detail))
    last = referees[-1] if referees else None
    return Verdict(
        scenario=sc.name,
        path=sc.path,
        seed=seed,
        engine=engine,
        passed=not failures,
        failures=tuple(failures),
        digest=total,
        score=(last.score_a, last.score_b) if last else (0, 0),
        ticks=worlds[-1].tick if worlds else 0,
        record=record,
        drawn=sc.drawn(seed),
        seconds=time.perf_counter() - t0,
    )
