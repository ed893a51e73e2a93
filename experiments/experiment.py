"""`arena experiment run FILE`: every match of an experiment (experiments/design.py),
on this machine (`--jobs`) or a Ray cluster (`--ray`), one tidy row per match, then the
per-cell means with their intervals, a plot per response and a report
(experiments/experiment_report.py).

Every match is played by `_play`, the one place that calls an engine. A row is written
atomically to `<out>/matches/<id>.json` as its match ends, so `--resume` plays only what is
missing, after Ctrl-C, a crash or a lost Ray node. Each cell's configuration is written to
`<out>/cells/<cell>.toml`: `arena match --config` of that file with the row's seed and
strategies plays the very match of the row (the same digest).
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from arena.config import ConfigError, MatchConfig
from arena.experiments.design import COVERAGE, Experiment
from arena.experiments.fixtures import write_atomic
from arena.runtime import matchfile

if TYPE_CHECKING:
    from arena.match import MatchResult

SWAPPED = "-ends-swapped"  # cells/c000-ends-swapped.toml: a cell whose team settings swap with the ends
ATTEMPTS = 2  # a match that fails is played once more, then recorded as failed


@dataclass
class RunOptions:
    jobs: int = 0  # 0: one per core; 1: in this process
    ray: str | None = None  # None: local; "": a local Ray instance; "auto" or HOST:PORT
    out: Path = Path("experiment")
    resume: bool = False
    progress: bool = True


# ------------------------------------------------------------------ one match
def _play(cfg: MatchConfig, engine: str, watch: tuple[str, ...] = ()) -> MatchResult:
    """Play one match on `engine` (arena.match: the one way to play a match); `watch`: keys whose
    payloads the result keeps (`frames`)."""
    from arena.match import play

    return play(cfg, engine=engine, watch=watch)


def play_one(cfg: MatchConfig, engine: str, facts: bool, run: Callable[[MatchConfig, str], dict] | None = None) -> dict:
    """One match: its score, metres per robot, digest, CPU time and, with `facts`, the `arena facts`
    measures of both teams; a worker's task. `team_view` turns it into one team's responses.
    `run`: a base's own way to play `cfg` (a scenario's run and verdict, scenarios/experiment.py)."""
    cpu0 = time.process_time()
    if run is not None:
        out = run(cfg, engine)
        out["cpu_s"] = round(time.process_time() - cpu0, 4)
        return out
    m = _play(cfg, engine, ("world", "referee") if facts else ())
    if m.void:  # a void match is no result (match/faults.py)
        raise RuntimeError("void: " + "; ".join(m.outcome_reasons or ["no reason given"]))
    out = {"score": list(m.score), "robots": m.robots, "distance_m": dict(m.distance_m), "digest": m.digest}
    if facts:
        out["facts"] = facts_of(cfg, m)
    out["cpu_s"] = round(time.process_time() - cpu0, 4)
    return out


def team_view(got: dict, team: str, share: int = 1) -> dict:
    """The responses of `team` in a match `play_one` played; `share`: rows that show this one match
    (its CPU time is split among them, so the rows' CPU adds up to what was played)."""
    out = responses(got, team)
    if "facts" in got:
        out.update(got["facts"][team])
    out.update(got.get("extra", {}))  # a scenario's pass, drawn values and failed expectations
    out["digest"] = got["digest"]
    out["cpu_s"] = round(got["cpu_s"] / share, 4)
    return out


def responses(m: dict, team: str) -> dict:
    """Points (3/1/0), goal difference, W/D/L, goals for and against, metres per robot, of `team`."""
    mine, theirs = (m["score"][0], m["score"][1]) if team == "a" else (m["score"][1], m["score"][0])
    out = {
        "points": 3 if mine > theirs else 1 if mine == theirs else 0,
        "goal_diff": mine - theirs,
        "win": int(mine > theirs),
        "draw": int(mine == theirs),
        "loss": int(mine < theirs),
        "goals_for": mine,
        "goals_against": theirs,
    }
    for n in range(m["robots"]):
        out[f"{COVERAGE}{n}"] = m["distance_m"].get(f"{team}/{n}", 0.0)
    return out


def facts_of(cfg: MatchConfig, m: MatchResult) -> dict:
    """The `arena facts` measures of each team (recording/analysis/facts.py over the watched frames)."""
    import msgspec

    from arena.recording.analysis.facts import measure
    from arena.schemas.messages import Referee, World

    worlds = [msgspec.msgpack.decode(raw, type=World) for raw in m.frames["world"]]
    referee = {r.tick: r for r in (msgspec.msgpack.decode(raw, type=Referee) for raw in m.frames["referee"])}
    extra = {"log": m.referee_log, "score": m.score, "events": m.events}  # the referee's summary
    f = measure(cfg, worlds, referee, extra, m.distance_m)
    return {
        team: {"shots": t.shots, "on_target": t.on_target, "saves": t.saves, "blocks": t.blocks}
        for team, t in zip("ab", f.teams)
    }


# ------------------------------------------------------------------ the run
class Run:
    """The matches of one experiment into `out`; `play()` returns whether it was interrupted."""

    def __init__(self, exp: Experiment, opts: RunOptions, source: str):
        self.exp, self.opts = exp, opts
        self.out = opts.out
        self.matches = exp.matches()
        self.by_id = {m["id"]: m for m in self.matches}
        self.rows: dict[str, dict] = {}
        self._prepare(source)

    def _prepare(self, source: str) -> None:
        out = self.out
        if out.exists() and not out.is_dir():
            raise ConfigError(f"--out {out} exists and is not a directory")
        kept = out / "experiment.toml"
        if kept.exists():
            if not self.opts.resume:
                raise ConfigError(f"--out {out} holds an experiment already: --resume to continue it, or another --out")
            if kept.read_text() != source:
                raise ConfigError(f"--resume: {kept} differs from the file given; the rows would not belong together")
        (out / "matches").mkdir(parents=True, exist_ok=True)
        (out / "cells").mkdir(exist_ok=True)
        write_atomic(kept, source)
        for c, cfg in enumerate(self.exp.configs if self.exp.scenario is None else ()):
            write_atomic(out / "cells" / f"c{c:03d}.toml", matchfile.dump(cfg))
            swapped = self.exp.match_config({"cell": c, "seed": cfg.seed, "team": "b", "opponent": cfg.away})
            if swapped.params != cfg.params:  # team settings: on the swapped ends they are the other team's
                write_atomic(out / "cells" / f"c{c:03d}{SWAPPED}.toml", matchfile.dump(swapped))
        if self.opts.resume:
            for m in self.matches:
                f = out / "matches" / f"{m['id']}.json"
                if f.exists():
                    with contextlib.suppress(json.JSONDecodeError, OSError):
                        self.rows[m["id"]] = json.loads(f.read_text())

    def row(self, m: dict, got: dict | None, reason: str, attempts: int) -> dict:
        cell = self.exp.cells[m["cell"]]
        cfg = self.exp.match_config(m)
        row = {"match": m["id"], "cell": f"c{m['cell']:03d}", **cell}
        row |= {"strategy": self.exp.configs[m["cell"]].home, "opponent": m["opponent"], "seed": m["seed"]}
        row |= {"team": m["team"], "team_a": cfg.home, "team_b": cfg.away, "status": "ok" if got else "failed"}
        if self.exp.scenario is None:
            row["config"] = self.config_file(m)
        row |= got or {"reason": reason}
        row["attempts"] = attempts
        write_atomic(self.out / "matches" / f"{m['id']}.json", json.dumps(row))
        return row

    def config_file(self, m: dict) -> str:
        """The file (below `out`) that `arena match --config` plays this match from, with the row's seed
        and strategies: the cell's, or on the swapped ends with team settings, the cell's swapped."""
        cfg = self.exp.configs[m["cell"]]
        swapped = m["team"] == "b" and self.exp.match_config(m).params != cfg.params
        return f"cells/c{m['cell']:03d}{SWAPPED if swapped else ''}.toml"

    def todo(self) -> list[list[dict]]:
        """The matches still to play, grouped by configuration: in a round robin of cells, AD's match
        against AS with AD as team a is AS's against AD with AS as team b, played once for both rows."""
        groups: dict[str, list[dict]] = {}
        for m in self.matches:
            groups.setdefault(repr(self.exp.match_config(m)), []).append(m)
        todo = [g for g in groups.values() if any(m["id"] not in self.rows for m in g)]
        return sorted(todo, key=lambda g: g[0]["seed"])  # seed by seed: a run stopped early has every cell

    def play(self) -> bool:
        """Play what is missing; True if interrupted (Ctrl-C), with what was finished kept."""
        from arena.experiments.executor import Executor

        todo = self.todo()
        left = sum(len(g) for g in todo)
        bar = Bar(len(self.matches), len(self.matches) - left, self.opts.progress)
        if not todo:
            return False
        queue = list(reversed(todo))
        try:
            with bar, Executor(self.opts.jobs, self.opts.ray, self.out) as ex:
                while queue and ex.pending < ex.capacity:
                    group = queue.pop()
                    ex.submit((group, 1), self._task(group[0]))
                while ex.pending:
                    for (group, attempt), got, reason in ex.wait():
                        if got is None and attempt < ATTEMPTS:
                            ex.submit((group, attempt + 1), self._task(group[0]))
                            continue
                        for m in group:
                            view = team_view(got, m["team"], len(group)) if got else None
                            self.rows[m["id"]] = row = self.row(m, view, reason, attempt)
                            bar.advance(row)
                        if queue:
                            group = queue.pop()
                            ex.submit((group, 1), self._task(group[0]))
        except KeyboardInterrupt:
            return True
        return False

    def _task(self, m: dict) -> tuple:
        cfg = self.exp.match_config(m)
        if self.exp.scenario is not None:
            return (cfg, self.exp.engine, False, self.exp.scenario.task(self.exp.cells[m["cell"]]))
        return (cfg, self.exp.engine, self.exp.needs_facts)


def ray_task(task: tuple, driver: dict) -> dict:
    """A Ray task: the same soccer-arena as the driver's, then `play_one`; a failure is a reason."""
    from arena.experiments import cluster

    mine = cluster.fingerprint()
    if mine != driver:
        return {
            "reason": f"version mismatch: the worker has {cluster.describe(mine)}, "
            f"the driver has {cluster.describe(driver)}"
        }
    try:
        return play_one(*task)
    except Exception as exc:  # a failed match is a result for the driver
        return {"reason": f"{type(exc).__name__}: {exc}".splitlines()[0]}


class Bar:
    """Matches done, the rate and the time left: a bar on a terminal, else a line per match (stderr)."""

    def __init__(self, total: int, done: int, show: bool):
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        from arena.review.console import console

        self.total, self.done, self.fresh, self.show = total, done, 0, show
        self.t0 = time.monotonic()
        self.console = console(stderr=True)
        self.live = show and sys.stderr.isatty()
        columns = (
            TextColumn("[bold]experiment[/]"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[rate]}"),
            TextColumn("left"),
            TimeRemainingColumn(),
        )
        self.progress = Progress(*columns, console=self.console, disable=not self.live)
        self.task = self.progress.add_task("m", total=total, completed=done, rate="")

    def __enter__(self) -> Bar:
        self.progress.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        self.progress.__exit__(*exc)

    def rate(self) -> str:
        took = time.monotonic() - self.t0
        return f"{self.fresh / took * 60:.1f} matches/min" if took > 0 and self.fresh else ""

    def advance(self, row: dict) -> None:
        self.done += 1
        self.fresh += 1
        self.progress.update(self.task, advance=1, rate=self.rate())
        if self.show and not self.live:
            left = (self.total - self.done) * (time.monotonic() - self.t0) / self.fresh
            what = f"failed: {row['reason']}" if row["status"] != "ok" else f"{row['points']} points"
            if row["status"] == "ok" and "pass" in row:
                what = "passed" if row["pass"] else f"did not pass ({row['failures']})"
            self.console.print(
                f"[{self.done}/{self.total}] {row['match']}: {what} ({self.rate()}, {left:.0f} s left)",
                highlight=False,
            )


def run(exp: Experiment, opts: RunOptions, source: str) -> tuple[dict, bool]:
    """Play what is missing, then write rows.csv, rows.json, summary.json, the plots and report.md."""
    from arena.experiments import experiment_report

    r = Run(exp, opts, source)
    t0, cpu0 = time.monotonic(), _cpu()
    interrupted = r.play()
    rows = [r.rows[m["id"]] for m in r.matches if m["id"] in r.rows]
    summary = experiment_report.write(exp, rows, opts.out)
    summary["wall_s"] = round(time.monotonic() - t0, 2)
    summary["runner_cpu_s"] = round(_cpu() - cpu0, 3)
    summary["interrupted"] = interrupted
    return summary, interrupted


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (the pool's workers once shut down)."""
    me = os.times()
    return me.user + me.system + me.children_user + me.children_system
