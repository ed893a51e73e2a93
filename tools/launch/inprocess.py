"""`arena match --engine inprocess`: a whole match in one process and one thread.

The very same `Node` code as in a distributed match, driven cooperatively
(runtime/coop.py): each node's lockstep generator is resumed when the link it
waits on is ready, frames are the same msgpack bytes on an in-memory bus, and
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

import gc
import os
import time

import msgspec

from arena.processes import node_class
from arena.runtime.config import MatchConfig
from arena.runtime.coop import CoopBus, CoopTransport, NodeFailed, Task, drive
from arena.runtime.node import settle_heap
from arena.schemas.keys import Keys
from arena.schemas.messages import Summary

ENGINE = "inprocess"
LOCKSTEP_KINDS = {"engine", "referee", "basestation", "robot", "recorder"}  # what this engine can host


class InprocessError(RuntimeError):
    """The match could not be played to the end; the message says why (one line)."""


def _play(cfg: MatchConfig, watch: tuple[str, ...], record: str = ""):
    """`record`: the recorder's MCAP path ("" for none); the other nodes get only `cfg.tap`."""
    cfg = cfg.replace(tap=bool(record))
    bus = CoopBus()
    keys = Keys("inprocess")
    taps = {name: bus.subscribe(None, keys.key(name)) for name in watch}
    nodes = {
        str(p): node_class(p.kind)(
            p, cfg, CoopTransport(bus), keys, **({"path": record} if record and p.kind == "recorder" else {})
        )
        for p in cfg.processes()
    }
    recorder = nodes.pop("recorder", None)
    settle_heap()
    started = time.time()
    t0 = time.perf_counter()
    tasks = [Task(name, node.lockstep(), node.batch_flusher()) for name, node in nodes.items()]
    quit_early: set[str] = set()
    try:
        deadlocks = drive(bus, tasks, on_idle=recorder.pump if recorder is not None else None, quit_early=quit_early)
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
        nodes[tasks[0].name].log.error("%s", line)
    summaries: dict[str, Summary] = {}
    for task in tasks:
        node = nodes[task.name]
        node._wall_s = play
        node.play_started = started
        s = node.conclude()
        summaries[task.name] = msgspec.structs.replace(s, cpu_s=[round(task.busy_s, 3), 0.0])
    if recorder is not None:
        recorder.finish()
        summaries["recorder"] = recorder.conclude()
    gc.unfreeze()  # a worker plays many matches: let this one's objects go
    frames = {}
    for name, ch in taps.items():
        got = []
        while (raw := ch.try_recv()) is not None:
            got.append(raw)
        frames[name] = got
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


def play_match(cfg: MatchConfig, record: str = "") -> dict:
    """Play one match in-process and return the result dict of `arena match --json`; `record`: an MCAP path."""
    from arena.tools.launch.launcher import Collected, assemble

    if cfg.realtime:
        raise InprocessError("--engine inprocess plays in lockstep only (no --realtime)")
    if cfg.external:
        raise InprocessError("--engine inprocess has no external processes (--external needs --engine processes)")
    others = sorted({p.kind for p in cfg.processes()} - LOCKSTEP_KINDS)
    if others:
        raise InprocessError(f"--engine inprocess cannot host {', '.join(others)} (use --engine processes)")
    t_start = time.monotonic()
    launched = time.time()
    summaries, _, play, deadlocks, quit_early = _play(cfg, watch=(), record=record)
    lost = {name: "its loop ended while others still waited for it" for name in quit_early}
    got = Collected(summaries=summaries, started=0.0, ended=play, lost=lost)
    result = assemble(cfg.replace(tap=bool(record)), got, time.monotonic() - t_start, [], record=record)
    result["engine"] = ENGINE
    result["startup_seconds"] = round(summaries["engine"].extra["play_started"] - launched, 3)
    result["launch"] = ENGINE
    result["play_started_unix"] = summaries["engine"].extra["play_started"]
    result["pid"] = os.getpid()
    result["deadlocks"] = deadlocks
    return result
