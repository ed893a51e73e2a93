"""What a Ray task costs on its own, next to a match: docs/cluster.md quotes this script's output.

    pip install -e '.[cluster]' && python examples/cluster_overhead.py

Starts a local Ray instance, then prints medians of: ray.init, an empty task's
round trip on a warm worker, the first task on a fresh worker (its start-up),
and the version check a worker does once (git revision and source hash).
"""

from __future__ import annotations

import statistics
import time

import ray

from arena.experiments import cluster


def empty() -> int:
    return 0


def main(n: int = 50) -> None:
    t0 = time.monotonic()
    ray.init(address="local", num_cpus=2, logging_level="ERROR", log_to_driver=False, include_dashboard=False)
    print(f"ray.init (local instance, 2 CPUs): {time.monotonic() - t0:.2f} s")
    task = ray.remote(empty).options(num_cpus=1)
    t0 = time.monotonic()
    ray.get(task.remote())
    print(f"first task (a worker starts): {time.monotonic() - t0:.3f} s")
    rounds = []
    for _ in range(n):
        t0 = time.monotonic()
        ray.get(task.remote())
        rounds.append(time.monotonic() - t0)
    print(f"empty task round trip, warm worker: median {statistics.median(rounds) * 1e3:.2f} ms of {n}")
    check = ray.remote(cluster.fingerprint).options(num_cpus=1)
    t0 = time.monotonic()
    ray.get(check.remote())
    print(f"version check on a worker (first call: git + source hash): {time.monotonic() - t0:.3f} s")
    t0 = time.monotonic()
    cluster._FINGERPRINT = None
    cluster.fingerprint()
    print(f"the same check in the driver: {time.monotonic() - t0:.3f} s")
    ray.shutdown()


if __name__ == "__main__":
    main()
