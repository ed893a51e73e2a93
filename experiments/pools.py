"""Stopping a pool of worker processes (`arena tournament --engine inprocess`, `arena facts`).

Ctrl-C on a terminal reaches every process of the group, the workers too; SIGTERM
(`kill`, a service manager) reaches only the parent. A pool shut down with
`wait=True` then waited for every running match to end, minutes for a
2 × 300 s one, so stopping now kills the workers instead.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor


def stop(pool: ProcessPoolExecutor, now: bool) -> None:
    """Shut `pool` down: the running work finishes, or with `now` is killed; nothing queued starts."""
    workers = list((getattr(pool, "_processes", None) or {}).values())  # shutdown sets it to None
    pool.shutdown(wait=not now, cancel_futures=True)
    if now:
        for p in workers:
            if p.is_alive():
                p.kill()
