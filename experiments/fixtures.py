"""A tournament's fixtures and results: who plays whom with which seed, and what
each match gave (`Result`, one JSON file per match, written atomically)."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from itertools import combinations
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from arena.runtime import seeds

if TYPE_CHECKING:
    from arena.match import MatchResult

ABBREV = {"advance-dynamic": "AD", "advance-static": "AS", "basic-dynamic": "BD", "basic-static": "BS"}


def plural(n: int, word: str, words: str | None = None) -> str:
    """`1 leg`, `2 legs`, `1 match`, `3 matches`."""
    return f"{n} {word if n == 1 else (words or word + 's')}"


def short(name: str) -> str:
    return ABBREV.get(name, name)


def file_safe(name: str) -> str:
    """`short(name)` fit for a file name: a policy file's strategy by its prefix and file name."""
    kind, _, path = short(name).partition(":")
    return f"{kind}-{os.path.basename(path)}" if path else kind.replace("/", "-")


# ------------------------------------------------------------------ schedule
@dataclass(frozen=True)
class Fixture:
    index: int  # position in the schedule
    first: str  # pairing as listed (the column order of Table 1)
    second: str
    leg: int  # 1-based
    home: str
    away: str
    seed: int

    @property
    def id(self) -> str:
        """The match's file name stem: a name such as `policy:/runs/p.pkl` as `policy-p.pkl`."""
        return f"{self.index:03d}-{file_safe(self.first)}-{file_safe(self.second)}-leg{self.leg:02d}"


def schedule(strategies: list[str], legs: int, seed: int) -> list[Fixture]:
    """Every pairing `legs` times, home and away alternating, seeds from the tournament seed."""
    out: list[Fixture] = []
    for first, second in combinations(strategies, 2):
        for leg in range(1, legs + 1):
            home, away = (first, second) if leg % 2 == 1 else (second, first)
            match_seed = seeds.derive(seed, "tournament", first, second, leg) % (2**31)
            out.append(Fixture(len(out), first, second, leg, home, away, match_seed))
    return out


# ------------------------------------------------------------------- results
def fixture_fields(fx: Fixture) -> dict:
    """The fields a `Result` repeats from its fixture."""
    return {k: getattr(fx, k) for k in ("first", "second", "leg", "home", "away", "seed")}


@dataclass
class Result:
    id: str
    first: str
    second: str
    leg: int
    home: str
    away: str
    seed: int
    status: str  # "ok" or "failed"
    score: list[int] = field(default_factory=lambda: [0, 0])  # [home, away]
    distance_m: dict[str, float] = field(default_factory=dict)  # "a/1" -> m
    reason: str = ""
    attempts: int = 0
    wall_seconds: float = 0.0
    rtf: float = 0.0
    digest: str = ""
    engine: str = "processes"  # which engine played it (arena match --engine)
    faults: list[dict] = field(default_factory=list)  # a team's crashed process: the match counts (match/faults.py)

    @classmethod
    def played(cls, fx: Fixture, m: MatchResult, attempts: int, wall_seconds: float, engine: str) -> Result:
        """Fixture `fx`'s result from its match's `m` (one that `void_reason` accepted)."""
        return cls(
            id=fx.id,
            status="ok",
            score=list(m.score),
            distance_m=dict(m.distance_m),
            attempts=attempts,
            wall_seconds=round(wall_seconds, 2),
            rtf=m.rtf,
            digest=m.digest,
            engine=engine,
            faults=msgspec.to_builtins(m.faults),  # as a match's JSON says them (a Result is JSON)
            **fixture_fields(fx),
        )

    @classmethod
    def failed(cls, fx: Fixture, reason: str, attempts: int, engine: str) -> Result:
        return cls(id=fx.id, status="failed", reason=reason, attempts=attempts, engine=engine, **fixture_fields(fx))

    def goals(self, team: str) -> tuple[int, int]:
        """(for, against) for `team` in this match."""
        h, a = self.score
        return (h, a) if team == self.home else (a, h)

    def robot_distance(self, team: str, n: int) -> float | None:
        side = "a" if team == self.home else "b"
        return self.distance_m.get(f"{side}/{n}")


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def load_results(directory: Path) -> dict[str, Result]:
    out: dict[str, Result] = {}
    if not directory.is_dir():
        return out
    for f in sorted(directory.glob("*.json")):
        try:
            r = Result(**json.loads(f.read_text()))
        except (ValueError, TypeError):
            continue  # a torn or foreign file: the match is simply played again
        out[r.id] = r
    return out


def void_reason(m: MatchResult) -> str:
    """Why a match is no result ("" if it is one): a void match never counts (match/faults.py)."""
    if m.outcome == "void" or m.void:
        return "void: " + "; ".join(m.outcome_reasons or ["no reason given"])
    return ""
