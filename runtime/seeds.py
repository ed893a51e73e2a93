"""One master seed derives every component's seed.

`derive(master, "link", "wifi", "report/a/1")` hashes the master seed and the
component's path with BLAKE2b, so adding a component never shifts the seeds of
the others, and every process can derive the seeds it needs on its own.
"""

from __future__ import annotations

import hashlib
import random


def derive(master: int, *path: object) -> int:
    """A 63-bit seed for the component named by `path`."""
    h = hashlib.blake2b(digest_size=8, person=b"soccer-arena")
    h.update(str(int(master)).encode())
    for part in path:
        h.update(b"\x1f")
        h.update(str(part).encode())
    return int.from_bytes(h.digest(), "big") >> 1


def rng(master: int, *path: object) -> random.Random:
    """A private `random.Random` for one component (never the global one)."""
    return random.Random(derive(master, *path))
