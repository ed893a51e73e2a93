"""Playing a tournament's fixtures on this machine: each a match process group
(`python -m arena.match`, handed its whole configuration: match/child.py),
or with `--engine inprocess` a match on a worker process of a pool; one retry, a
failure recorded with its reason; Ctrl-C stops what runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

from arena.experiments import pools
from arena.experiments.fixtures import Fixture, Result, void_reason, write_atomic
from arena.match import child

if TYPE_CHECKING:
    from arena.config import MatchConfig
    from arena.experiments.tournament import TournamentOptions
    from arena.match import MatchResult


class Runner:
    """Plays fixtures as match subprocesses (or on a pool's workers); stoppable from the main thread."""

    def __init__(self, opts: TournamentOptions, out: Path):
        self.opts = opts
        self.matches_dir = out / "matches"
        self.matches_dir.mkdir(parents=True, exist_ok=True)
        self.logs_dir = out / "logs"
        self.logs_dir.mkdir(exist_ok=True)
        self._lock = threading.Lock()
        self._running: set[subprocess.Popen] = set()
        self.stopping = False
        self.engine = opts.engine
        # --engine inprocess: one worker process per job, each playing whole
        # matches in one thread, one after another; it imports once, not per match.
        self.pool = None
        if self.engine == "inprocess":
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            self.pool = ProcessPoolExecutor(
                max_workers=opts.jobs or default_jobs(),
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_worker_init,
            )

    def match_config(self, fx: Fixture) -> MatchConfig:
        """The fixture's match: the tournament's base configuration with its seed and teams."""
        return self.opts.match_config(fx.seed, fx.home, fx.away)

    def play_inprocess(self, fx: Fixture) -> Result | None:
        """`play` on a worker process of the pool (--engine inprocess)."""
        reason = ""
        for attempt in (1, 2):
            if self.stopping:
                return None
            t0 = time.monotonic()
            try:
                m = self.pool.submit(_play_inprocess, self.match_config(fx)).result()
            except Exception as exc:  # a failed match is recorded, never fatal to the tournament
                if self.stopping:
                    return None
                reason = f"{type(exc).__name__}: {exc}".splitlines()[0]
                (self.logs_dir / f"{fx.id}.log").write_text(reason + "\n")
                continue
            if void := void_reason(m):  # a void match is no result, whichever engine played it
                reason = void
                (self.logs_dir / f"{fx.id}.log").write_text(reason + "\n")
                continue
            r = Result.played(fx, m, attempt, time.monotonic() - t0, self.engine)
            write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
            return r
        r = Result.failed(fx, reason, 2, self.engine)
        write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
        return r

    def close(self) -> None:
        if self.pool is not None:
            pools.stop(self.pool, now=self.stopping)

    def play(self, fx: Fixture) -> Result | None:
        """Play one fixture (one retry on failure). None if stopped by Ctrl-C."""
        if self.pool is not None:
            return self.play_inprocess(fx)
        reason = ""
        cfg = self.match_config(fx)
        timeout = 120.0 + 2.0 * cfg.half_time  # generous: rtf >= 1 plus start-up
        for attempt in (1, 2):
            if self.stopping:
                return None
            t0 = time.monotonic()
            log = open(self.logs_dir / f"{fx.id}.log", "w")
            proc, given = child.start(cfg, self.engine, stderr=log, start_new_session=True)
            with self._lock:
                self._running.add(proc)
            try:
                out, _ = proc.communicate(input=given, timeout=timeout)
            except subprocess.TimeoutExpired:
                proc.send_signal(signal.SIGINT)
                out, _ = proc.communicate()
                reason = f"timed out after {timeout:g} s"
            finally:
                with self._lock:
                    self._running.discard(proc)
                log.close()
            if self.stopping:
                return None
            if proc.returncode == 0:
                try:
                    m = child.decode(out)
                except ValueError as exc:
                    reason = str(exc)
                    continue
                if void := void_reason(m):
                    reason = void
                    continue
                r = Result.played(fx, m, attempt, time.monotonic() - t0, self.engine)
                write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
                return r
            tail = (self.logs_dir / f"{fx.id}.log").read_text(errors="replace").strip().splitlines()
            reason = reason or (tail[-1] if tail else f"exit code {proc.returncode}")
        r = Result.failed(fx, reason, 2, self.engine)
        write_atomic(self.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
        return r

    def stop(self) -> None:
        self.stopping = True
        if self.pool is not None:
            self.close()
        with self._lock:
            running = list(self._running)
        for p in running:
            if p.poll() is None:
                p.send_signal(signal.SIGINT)  # the match stops its whole process group


def _worker_init() -> None:
    """An --engine inprocess worker: dies with the tournament, leaves Ctrl-C to it, imports once."""
    import ctypes

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def _play_inprocess(cfg: MatchConfig) -> MatchResult:
    from arena.match import play

    result = play(cfg)
    result.summaries = {}  # what the tournament reads is the result's own fields: not pickled back
    return result


def default_jobs() -> int:
    """One match per core.

    A lockstep match keeps its cores only ~80 % busy (it waits on its own
    critical path) and spends ~2 s starting its processes, so a second match
    fills the gaps. On the 2-core development machine, 6 matches of 2 x 60 s
    (AD, BS, AS, 2 legs) took 56.6 and 56.3 s with one at a time and 43.8 and
    46.3 s with two, with the same results and digests.
    """
    return max(1, os.cpu_count() or 1)


def play_local(jobs: int, runner: Runner, todo: list[Fixture], arrived) -> bool:
    """`jobs` (0: one per core) matches at once in a thread pool; arrived(Result) as each is in. Returns interrupted."""
    with ThreadPoolExecutor(max_workers=jobs or default_jobs()) as pool:
        pending = {pool.submit(runner.play, fx) for fx in todo}
        try:
            while pending:
                done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                for f in done:
                    r = f.result()
                    if r is not None:
                        arrived(r)
        except KeyboardInterrupt:
            runner.stop()
            for f in pending:
                f.cancel()
            return True
    return False
