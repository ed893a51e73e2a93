"""`arena bench refbox`: what the bridge's parsing costs on hostile input, per kB, at two sizes.

Each input is a whole message as a base station could send it (the worldstate check runs on the
text up to its NUL; the command reader on a RefBox's stream). Linear parsing costs about the same
per kB at 100 kB and at 1 MB (a ratio of 1 to 3, from the memory of ten times the pieces); a
quadratic step shows a ratio near 10.
"""

from __future__ import annotations

import json
import statistics
import time
from collections.abc import Callable

from arena.rules import refbox_protocol as rp

SIZES = (100_000, 1_000_000)  # [bytes] the RefBox's limit, and ten times it


def _inputs(n: int) -> dict[str, tuple[Callable[[str], object], str]]:
    check = rp.validate_worldstate
    return {
        "escaped quotes": (check, '"' + '\\"' * (n // 2)),
        "quote-bracket pairs": (check, '"[' * (n // 2)),
        "backslashes": (check, "\\" * n),
        "open brackets": (check, "[" * n),
        "long good string": (check, json.dumps({"type": "worldstate", "intention": "x" * n})),
        "legacy garbage": (lambda text: _feed(text.encode()), "?" * n),
        "json command cut in 1 kB": (lambda text: _feed(text.encode(), 1024), "{" + " " * n),
    }


def _feed(data: bytes, chunk: int = 4096) -> None:
    reader = rp.CommandReader()
    for i in range(0, len(data), chunk):
        reader.feed(data[i : i + chunk])


def bench_refbox(runs: int, as_json: bool) -> int:
    rows = []
    for name in _inputs(1):
        per_kb = []
        for n in SIZES:
            fn, text = _inputs(n)[name]
            times = []
            for _ in range(runs):
                t0 = time.perf_counter()
                fn(text)
                times.append(time.perf_counter() - t0)
            per_kb.append(statistics.median(times) / (len(text) / 1000) * 1e6)
        rows.append({"input": name, "us_per_kb": per_kb, "ratio": per_kb[1] / per_kb[0]})
    if as_json:
        print(json.dumps({"sizes": SIZES, "runs": runs, "rows": rows}, indent=2))
        return 0
    print(f"refbox parsing, median of {runs} runs: us per kB at 100 kB and 1 MB (quadratic: ratio near 10)")
    for r in rows:
        a, b = r["us_per_kb"]
        print(f"  {r['input']:<26} {a:8.2f} {b:8.2f}   ratio {r['ratio']:.2f}")
    return 0
