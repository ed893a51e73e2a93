"""`arena replay FILE.mcap --process robot/a/1`: one process against its recorded inputs.

A lockstep match is a pure function of (configuration, seed), and so is each
process given its inputs. Replay rebuilds the `MatchConfig` from the file's
metadata and has the in-process engine build that ONE process's node
(`InProcess.stepped`, the very `Node` class of processes/) over its in-memory
bus, in this process and this thread, driven cooperatively (runtime/coop.py):

1. every frame recorded on each of its input keys is put on the bus, in the
   order its sender sent them. The node's own link emulators, seeded from the
   configuration, drop and delay exactly the frames they did in the match;
2. the node's lockstep generator is driven to its end. It uses every recorded
   frame; where the recording ends (a truncated file, or a match stopped by
   Ctrl-C or SIGTERM, whose processes each stopped at their own tick) nobody else can send,
   and the driver gives those waits up at once, as a match gives up on a
   process that has gone;
3. what the node publishes on its output keys is compared, frame by frame,
   with what the file recorded for that process.

The result is `match: true`, or the first frame (lowest tick) that differs,
with its key and both decoded values. Any robot, both base stations, the
referee and the engine can be replayed. A real-time match is not
deterministic and cannot be replayed.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from dataclasses import dataclass, field

import msgspec

from arena.config import ConfigError, ProcessId
from arena.match import InProcess, counted
from arena.recording.reader import Recording, RecordingError, load
from arena.runtime.coop import NodeFailed
from arena.runtime.lockstep import BATCH_HEADS, decode_batch
from arena.schemas.messages import KillProcess


class ReplayError(ValueError):
    """The replay cannot be done; the message is one line."""


@dataclass
class Difference:
    tick: int
    key: str
    index: int  # frame number on that key, from 0
    recorded: object  # decoded msgpack (None: no such frame recorded)
    replayed: object  # decoded msgpack (None: the replay sent no such frame)
    fields: list[str] = field(default_factory=list)  # top-level fields that differ


@dataclass
class ReplayResult:
    process: str
    match: bool
    frames: int  # output frames compared
    keys: dict[str, int]  # output frames compared per key
    first_difference: Difference | None = None
    digest_match: bool | None = None  # the replay's digest against the recorded Summary's (None: not recorded)
    note: str = ""

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def _decode(payload: bytes | None) -> object:
    if payload is None:
        return None
    try:
        return msgspec.msgpack.decode(payload)
    except msgspec.DecodeError:
        return payload  # not msgpack (a damaged or hostile file): compared as bytes


def _difference(key: str, index: int, recorded: bytes | None, replayed: bytes | None) -> Difference:
    a, b = _decode(recorded), _decode(replayed)
    frame = a if isinstance(a, dict) else b
    tick = frame.get("tick", -1) if isinstance(frame, dict) else -1
    fields = []
    if isinstance(a, dict) and isinstance(b, dict):
        fields = sorted(k for k in a.keys() | b.keys() if a.get(k) != b.get(k))
    return Difference(tick=tick, key=key, index=index, recorded=a, replayed=b, fields=fields)


def replay(source: str | Recording, process: str) -> ReplayResult:  # noqa: C901, PLR0912 - one branch per way a recording can fail to replay
    """Replay `process` (e.g. "robot/a/1", "a/1", "basestation/b") from a recording."""
    rec = source if isinstance(source, Recording) else load(source)
    try:
        pid = ProcessId.parse(process)
    except ConfigError as exc:
        raise ReplayError(str(exc)) from None
    cfg = rec.cfg
    if pid.kind in ("recorder", "viewer"):
        raise ReplayError(f"{process}: only the lockstep nodes replay (engine, referee, base stations, robots)")
    if pid not in cfg.processes():
        raise ReplayError(f"{process}: no such process in this recording ({cfg.robots} robots per team)")
    if pid.kind == "refbox":
        raise ReplayError("refbox: the RefBox bridge replays nothing: its worldstates came from outside the match")
    if cfg.realtime:
        raise ReplayError("this match ran with --realtime, which is not deterministic: only lockstep matches replay")
    killed = [(a.process, s.at) for s in cfg.scenario.steps for a in s.actions if isinstance(a, KillProcess)]
    if killed:  # the kill cuts a loop short where replay would go on; every node after it would differ
        who, at = killed[0]
        when = f"at tick {at}" if at >= 0 else "when its condition held"
        raise ReplayError(f"this match's scenario killed {who} {when} (a kill step): only matches without one replay")
    cfg = cfg.replace(tap=False)  # the replayed node taps nothing
    name = str(pid)
    match = InProcess().stepped(cfg, only=(pid,), match="replay")
    bus, keys, node = match.bus, match.keys, match.nodes[name]
    task = node.driver  # its `Task`: only its lockstep is driven (no barrier; its summary below)
    task.steps = node.lockstep()
    outputs = [(keys.rel(ob.key), bus.subscribe(None, ob.key)) for ob in node.outbound]
    for ib in node.inbound:
        for payload in rec.payloads(keys.rel(ib.key)):
            bus.deliver(ib.key, payload)
    early = rec.ends_early
    if early:  # its inputs stop where the file does; giving up on every sender there is expected
        node.log.addFilter(lambda r: r.msg != "treating %s as dead: %s")
    try:
        match.drive([task])
    except NodeFailed as exc:
        raise exc.__cause__ from None  # the node's own error, as if it had run alone
    summary = [node.conclude()]

    first: Difference | None = None
    counts: dict[str, int] = {}
    for rel, channel in outputs:
        got = []
        while (raw := channel.try_recv()) is not None:  # a batch (`Outbound.batch`) is its frames, as tapped
            got.extend(decode_batch(raw) if raw[:1] and raw[0] in BATCH_HEADS else (raw,))
        want = rec.payloads(rel)
        if early:  # compare what both have: each process (and its recorded outputs) stopped at its own tick
            got, want = got[: len(want)], want[: len(got)]
        counts[rel] = min(len(got), len(want))
        for i in range(max(len(got), len(want))):
            a = want[i] if i < len(want) else None
            b = got[i] if i < len(got) else None
            if a != b:
                d = _difference(rel, i, a, b)
                if first is None or d.tick < first.tick:
                    first = d
                break
    recorded_summary = rec.summaries.get(name)
    digest_match = None
    if recorded_summary is not None and summary and not early:
        digest_match = recorded_summary.digest == summary[0].digest
    note = f"{early}: compared up to its end" if early else ""
    return ReplayResult(
        process=name,
        match=first is None,
        frames=sum(counts.values()),
        keys=counts,
        first_difference=first,
        digest_match=digest_match,
        note=note,
    )


def _describe(r: ReplayResult) -> str:
    if r.match:
        digest = {True: ", digest equal", False: ", but the digest differs", None: ""}[r.digest_match]
        return f"{r.process}: match: true ({r.frames} frames on {len(r.keys)} keys{digest})"
    d = r.first_difference
    lines = [f"{r.process}: match: false, first difference at tick {d.tick} on {d.key} (frame {d.index})"]
    if isinstance(d.recorded, dict) and isinstance(d.replayed, dict):
        for f in d.fields:
            lines.append(f"  {f}: recorded {d.recorded.get(f)!r}, replayed {d.replayed.get(f)!r}")
    else:
        lines.append(f"  recorded: {d.recorded!r}")
        lines.append(f"  replayed: {d.replayed!r}")
    return "\n".join(lines)


def main(path: str, processes: list[str], as_json: bool = False) -> int:
    try:
        rec = load(path)
        every = [str(p) for p in counted(rec.cfg)]
        names = every if "all" in processes else processes
        results = [replay(rec, p) for p in names]
    except (RecordingError, ReplayError) as exc:
        print(f"arena replay: error: {exc}", file=sys.stderr)
        return 2
    ok = all(r.match for r in results)
    if as_json:
        out = results[0].to_dict() if len(results) == 1 else {"match": ok, "results": [r.to_dict() for r in results]}
        print(json.dumps(out, indent=2))
    else:
        for r in results:
            print(_describe(r))
            if r.note:
                print(f"  ({r.note})")
    return 0 if ok else 1
