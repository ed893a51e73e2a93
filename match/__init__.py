"""One way to play a match: `play(cfg, engine=..., record=..., watch=...)` takes a `MatchConfig`
and returns a typed `MatchResult`, whichever engine plays it.

Two engines (`engine(name)`, both an `Engine`): "processes", every process its own OS process
over zenoh (tools/launch/launcher.py), and "inprocess", every node on this thread
(tools/launch/inprocess.py), with the same digests. The in-process engine also builds a match
to be driven a stretch at a time (`InProcess.stepped`: the learning environments, replay).
`counted` is the one place that says which processes' digests make the match's.

May import every package below it (tools.launch included); imported by tools.review,
tools.experiments, scenarios, learn and the command line, never by them in turn."""

from __future__ import annotations

from arena.match.engines import ENGINES, Engine, InProcess, Processes, engine, play
from arena.tools.launch.result import JoinError, MatchError, MatchResult, combined_digest, counted

__all__ = [
    "ENGINES",
    "Engine",
    "InProcess",
    "JoinError",
    "MatchError",
    "MatchResult",
    "Processes",
    "combined_digest",
    "counted",
    "engine",
    "play",
]
