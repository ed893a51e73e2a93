"""Where an experiment's matches run: in this process (`--jobs 1`), on a pool of worker
processes (`--jobs N`, one match per worker at a time, each importing once), or as Ray
tasks (`--ray [ADDRESS]`, experiments/cluster.py's connection and version check).

Every task is `play_one(cfg, engine, facts)` (experiments/experiment.py); a
task that fails comes back as its reason, never as an exception, so the caller decides
whether to play it again.
"""

from __future__ import annotations

import contextlib
import multiprocessing
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path


def _reason(exc: BaseException) -> str:
    return (f"{type(exc).__name__}: {exc}".splitlines() or ["failed"])[0]


class Executor:
    """submit(key, task); wait() -> [(key, result or None, reason)] as tasks end; a context manager."""

    def __init__(self, jobs: int, ray: str | None, log_dir: Path):
        from arena.experiments.matches import default_jobs

        self.jobs = jobs or default_jobs()
        self.mode = "ray" if ray is not None else "here" if self.jobs == 1 else "pool"
        self.queue: deque = deque()  # "here": tasks waiting to be played in this process
        self.running: dict = {}  # future or Ray ref -> key
        self.pool = self.ray = None
        self.stack = contextlib.ExitStack()
        if self.mode == "pool":
            from arena.experiments.matches import _worker_init

            context = multiprocessing.get_context("spawn")
            self.pool = ProcessPoolExecutor(self.jobs, mp_context=context, initializer=_worker_init)
        elif self.mode == "ray":
            self._connect(ray, log_dir)

    def _connect(self, address_text: str, log_dir: Path) -> None:
        from arena.experiments import cluster
        from arena.experiments.experiment import ray_task

        address = cluster.parse_address(address_text)
        log = self.stack.enter_context(open(log_dir / "ray-driver.log", "a"))
        self.stack.enter_context(contextlib.redirect_stdout(log))  # Ray's prints stay out of --json
        self.ray = cluster.connect(address, float(self.jobs))
        self.stack.callback(cluster._shutdown, self.ray)
        self.remote = self.ray.remote(ray_task).options(num_cpus=1, max_retries=cluster.SYSTEM_RETRIES)
        self.driver = cluster.fingerprint()
        if address is not None:  # an existing cluster decides how many run at once
            self.jobs = max(self.jobs, int(self.ray.cluster_resources().get("CPU", self.jobs)))

    @property
    def capacity(self) -> int:
        """Tasks worth having submitted: one per worker, and one more each so that none idles."""
        return 1 if self.mode == "here" else 2 * self.jobs if self.mode == "pool" else self.jobs

    @property
    def pending(self) -> int:
        return len(self.queue) + len(self.running)

    def submit(self, key, task: tuple) -> None:
        from arena.experiments.experiment import play_one

        if self.mode == "here":
            self.queue.append((key, task))
        elif self.mode == "pool":
            self.running[self.pool.submit(play_one, *task)] = key
        else:
            self.running[self.remote.remote(task, self.driver)] = key

    def wait(self, timeout: float = 0.5) -> list[tuple]:
        """What ended since the last call (in this process: the next task, played now)."""
        from arena.experiments.experiment import play_one

        if self.mode == "here":
            if not self.queue:
                return []
            key, task = self.queue.popleft()
            try:
                return [(key, play_one(*task), "")]
            except Exception as exc:  # a failed match is a reason, never the end of the run
                return [(key, None, _reason(exc))]
        if self.mode == "pool":
            done, _ = wait(self.running, timeout=timeout, return_when=FIRST_COMPLETED)
            out = []
            for fut in done:
                key = self.running.pop(fut)
                try:
                    out.append((key, fut.result(), ""))
                except Exception as exc:  # the match failed in the worker
                    out.append((key, None, _reason(exc)))
            return out
        ready, _ = self.ray.wait(list(self.running), num_returns=1, timeout=timeout)
        out = []
        for ref in ready:
            key = self.running.pop(ref)
            try:
                got = self.ray.get(ref)
            except Exception as exc:  # the task failed, Ray's retries used up
                got = {"reason": f"task failed: {str(exc).strip().splitlines()[-1][:300]}"}
            out.append((key, None, got["reason"]) if "reason" in got else (key, got, ""))
        return out

    def abandon(self) -> None:
        """Drop what still runs (a test that has decided): a pool's workers are killed, not waited for."""
        from arena.experiments import pools

        self.queue.clear()
        if self.pool is not None and self.running:
            pools.stop(self.pool, now=True)
            self.pool = None
        self.running.clear()

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        from arena.experiments import pools

        if self.pool is not None:  # stopped (Ctrl-C, an error): the workers are killed, not waited for
            pools.stop(self.pool, now=kind is not None)
        self.stack.close()
