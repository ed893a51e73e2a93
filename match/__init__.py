"""One way to play a match: `play(cfg, engine=..., record=..., watch=...)` takes a `MatchConfig`
and returns a typed `MatchResult` (result.py), whichever engine plays it.

Two engines (`engine(name)`, both an `Engine`, engines.py): "processes", every process its own
OS process over zenoh, started, supervised and collected by the launcher (launcher.py, with the
OS processes in children.py, the fork server in zygote.py and forkstart.py, the `Job` every
process starts from in run.py, supervise.py, joins.py of processes started by hand, the witness
of external digests, fault blame in faults.py), and "inprocess", every node on this thread
(inprocess.py), with the same digests. The in-process engine also builds a match to be driven
a stretch at a time (`InProcess.stepped`: the learning environments, replay). `counted` is the
one place that says which processes' digests make the match's. Also here: `arena up`'s compose
files (compose.py) and a match in a process of its own (child.py, `python -m arena.match`).

May import every package below it (processes and down); imported by review, experiments,
scenarios, learn and the command line, never by them in turn."""

from __future__ import annotations

from arena.match.engines import ENGINES, Engine, InProcess, Processes, engine, play
from arena.match.result import JoinError, MatchError, MatchResult, combined_digest, counted

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
