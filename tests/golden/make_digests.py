"""Writes tests/golden/digests.json: per-process digests of 20 fixed matches.

Run once on a build whose behaviour is the reference; tests/unit/test_golden_digests.py
then replays the same 20 configurations and requires the same digests. A change that
alters behaviour on purpose regenerates the file in its own commit and says why.

    python tests/golden/make_digests.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from arena.config import MatchConfig
from arena.match.inprocess import play_in_process

HERE = Path(__file__).resolve().parent
STRATS = ("basic-static", "basic-dynamic", "advance-static", "advance-dynamic", "chase")
LINKS = ("ideal", "lan", "wifi", "congested-wifi")

# 20 configurations: every strategy at home and away, every link preset, 2 and 3 robots.
CONFIGS = [
    dict(
        seed=100 + i,
        home=STRATS[i % 5],
        away=STRATS[(i * 3 + 1) % 5],
        link=LINKS[i % 4],
        robots=3 if i % 5 else 2,
        half_time=4.0,
    )
    for i in range(20)
]


def digests(spec: dict) -> dict[str, str]:
    summaries, _ = play_in_process(MatchConfig(**spec), watch=())
    return {name: s.digest for name, s in sorted(summaries.items())}


def main() -> int:
    out = [dict(config=spec, digests=digests(spec)) for spec in CONFIGS]
    (HERE / "digests.json").write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {len(out)} configurations")
    return 0


if __name__ == "__main__":
    sys.exit(main())
