"""`arena match --engine inprocess`: a whole match in one process and one thread.

The very same `Node` code as in a distributed match, each node played by
`Node.playing` under a cooperative driver (runtime/coop.py `play`): each
node's lockstep generator is resumed when the link it waits on is ready, frames are the same msgpack bytes on an in-memory bus, and
no node has a thread of its own. The per-process digests are those of the
distributed run (tests/golden/digests.json pins 20 configurations; an
integration test compares against real processes over zenoh).

What differs from the distributed run is only what the machine does: one
interpreter, no zenoh, no start barrier or liveliness (every node is there by
construction), and per-node `cpu_s` is the wall time the single thread spent
in that node's loop. A recorded match (`record=PATH`) runs the recorder node
too: it drains the taps between rounds of the run queue and writes the same
MCAP message records as the distributed recorder.
"""

from __future__ import annotations

import os
import time
from typing import TYPE_CHECKING

from arena.config import MatchConfig, ProcessId
from arena.match.result import MatchError
from arena.processes import node_class
from arena.runtime import coop
from arena.runtime.coop import CoopBus, NodeFailed, Task
from arena.runtime.node import killed_at, match_heap
from arena.runtime.transport import MemoryTransport
from arena.schemas.keys import Keys

if TYPE_CHECKING:
    from arena.match.result import MatchResult
    from arena.runtime.node import Node
    from arena.schemas.messages import Summary

ENGINE = "inprocess"
LOCKSTEP_KINDS = {"engine", "referee", "basestation", "robot", "recorder"}  # what this engine can host


class InprocessError(MatchError):
    """The match could not be played to the end; the message says why (one line)."""


class Stepped:
    """A match built on this thread and not yet played: the in-memory `bus`, the `keys`, every
    lockstep node (`nodes`, by name, each driven by its own `coop.Task`), the recorder if the
    configuration has one, and a tap on each key of `watch` (`frames` drains it).

    `play()` plays it to the end (what `play_match` does); a caller that pauses the match drives
    the tasks itself and runs them a stretch at a time with `run()` (learn/match.py stops where a
    learner needs an action), or builds `only` some processes and feeds them recorded inputs
    (review/replay.py). `match`: the key prefix (never part of a digest)."""

    def __init__(
        self,
        cfg: MatchConfig,
        *,
        watch: tuple[str, ...] = (),
        record: str = "",
        only: tuple[ProcessId, ...] | None = None,
        match: str = "inprocess",
    ):
        self.cfg = cfg
        self.bus = bus = CoopBus()
        self.keys = keys = Keys(match)
        self.taps = {name: bus.subscribe(None, keys.key(name)) for name in watch}
        self.recorder = None
        self.nodes: dict[str, Node] = {}
        for p in cfg.processes() if only is None else only:
            if p.kind == "recorder":  # an observer: it drains the taps between rounds of the run queue
                self.recorder = node_class(p.kind)(p, cfg, MemoryTransport(bus), keys, path=record)
            else:
                self.nodes[str(p)] = node_class(p.kind)(p, cfg, MemoryTransport(bus), keys, driver=Task(str(p)))
        bus.straighten(ob for node in self.nodes.values() for ob in node.outbound)  # one call less a frame

    def frames(self, name: str) -> list[bytes]:
        """What arrived on the watched key `name` since the last call, in order."""
        ch, got = self.taps[name], []
        while (raw := ch.try_recv()) is not None:
            got.append(raw)
        return got

    def run(self) -> None:
        """Resume runnable tasks until none is (`coop.run_runnable`); a task that raises: `NodeFailed`."""
        coop.run_runnable(self.bus)

    def drive(self, tasks: list[Task]) -> list[str]:
        """Run `tasks` to their end (`coop.drive`); returns the deadlocks met."""
        return coop.drive(self.bus, tasks)

    def play(self, quit_early: set[str]) -> tuple[dict[str, Summary], list[str]]:
        """Play every node's match to the end (loop and summary; the recorder drains its taps between
        rounds): their summaries by name and the deadlocks met. `quit_early` collects the nodes whose
        loop ended while others still waited for them."""
        cfg, nodes, recorder = self.cfg, list(self.nodes.values()), self.recorder
        killed = frozenset(n.name for n in nodes if killed_at(cfg, n.name) >= 0)  # a scenario's `kill` steps
        return coop.play(self.bus, nodes, recorder.pump if recorder is not None else None, quit_early, killed)


def _play(cfg: MatchConfig, watch: tuple[str, ...], record: str = "", last: bool = False):
    """`record`: the recorder's MCAP path ("" for none); the other nodes get only `cfg.tap`;
    `last`: this process ends with the match (no collection of what it leaves, `match_heap`)."""
    with match_heap(collect=not last):  # a worker plays many matches: what this one leaves is collected as it returns
        return _play_here(cfg, watch, record)


def _play_here(cfg: MatchConfig, watch: tuple[str, ...], record: str):
    match = Stepped(cfg.replace(tap=bool(record)), watch=watch, record=record)
    recorder, nodes = match.recorder, list(match.nodes.values())
    quit_early: set[str] = set()
    t0 = time.perf_counter()
    try:
        summaries, deadlocks = match.play(quit_early)
    except NodeFailed as exc:
        if recorder is not None:
            recorder.finish()
        raise InprocessError(str(exc)) from exc.__cause__
    except KeyboardInterrupt:
        if recorder is not None:  # a whole file that says it was stopped, as the recorder process writes
            recorder.interrupted = "SIGINT"
            recorder.finish()
        raise
    play = time.perf_counter() - t0
    for line in deadlocks:
        nodes[0].log.error("%s", line)
    if recorder is not None:
        recorder.finish()
        summaries["recorder"] = recorder.conclude()
    frames = {name: match.frames(name) for name in watch}
    return summaries, frames, play, deadlocks, quit_early


def play_in_process(
    cfg: MatchConfig,
    watch: tuple[str, ...] = ("world",),
    timeout: float = 120.0,
    record: str = "",
):
    """Play `cfg` in this thread. Returns (summaries by process, {key name: [payload, ...]}).

    `record`: write the match to this MCAP file (the recorder node runs too).

    `timeout` is kept for callers of the threaded driver this replaced: a
    cooperative match cannot hang (a deadlock is detected, not waited out).
    """
    summaries, frames, _, _, _ = _play(cfg, watch, record)
    return summaries, frames


def play_match(cfg: MatchConfig, record: str = "", watch: tuple[str, ...] = (), last: bool = False) -> MatchResult:
    """Play one match in-process and return the result of `arena match --json`; `record`: an MCAP path;
    `watch`: keys whose payloads the result keeps (`frames`); `last`: this process ends with the match."""
    from arena.match.result import Collected, assemble

    if cfg.realtime:
        raise InprocessError("--engine inprocess plays in lockstep only (no --realtime)")
    if cfg.external:
        raise InprocessError("--engine inprocess has no external processes (--external needs --engine processes)")
    others = sorted({p.kind for p in cfg.processes()} - LOCKSTEP_KINDS)
    if others:
        raise InprocessError(f"--engine inprocess cannot host {', '.join(others)} (use --engine processes)")
    t_start = time.monotonic()
    launched = time.time()
    summaries, frames, play, deadlocks, quit_early = _play(cfg, watch=watch, record=record, last=last)
    lost = {name: "its loop ended while others still waited for it" for name in quit_early}
    got = Collected(summaries=summaries, started=0.0, ended=play, lost=lost)
    result = assemble(cfg.replace(tap=bool(record)), got, time.monotonic() - t_start, record=record)
    result.engine = ENGINE
    result.startup_seconds = round(summaries["engine"].extra["play_started"] - launched, 3)
    result.launch = ENGINE
    result.play_started_unix = summaries["engine"].extra["play_started"]
    result.pid = os.getpid()
    result.deadlocks = deadlocks
    result.frames = frames
    return result
