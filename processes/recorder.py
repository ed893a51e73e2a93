"""Recorder process: the match's MCAP log (docs/recording.md).

The recorder does not subscribe to the match's data keys: every other process
taps what it sends and publishes it in batches (runtime/tap.py), which costs
the match a fraction of what a second copy of every frame would. The recorder
collects the batches on `arena/<m>/tap/**` and writes:

* one MCAP channel per data key, topic = the key without `arena/<m>/`
  (`robot/a/1/cmd`), message encoding `msgpack`, the payload byte for byte, and
  a schema record named after the key's message type (schema encoding `""`:
  msgpack is self-describing; the types' JSON Schemas are in the `schemas`
  metadata, for information);
* `/scene` and `/referee_log`, the Foxglove layer (recording/scene.py);
* metadata `arena` (configuration, seed, strategies, git revision), `versions`,
  `schemas`, one `summary/<process>` per process Summary, and `recording`:
  `complete` only if every process's tap batches came without a gap and, per
  key, as many frames as its Summary says it sent; otherwise `gaps` lists,
  per process, the lost batch numbers and the keys whose counts differ.

Log time = publish time = the frame's tick x dt, in ns of simulated time.
Records are written in the order (tick, process in `cfg.processes()` order,
send order within the process), which depends only on (configuration, seed):
a process's batch carries a watermark tick, and frames are written once every
process's watermark has passed them.

Crash safety: SIGTERM and SIGINT finish the file (summary section, footer).
A chunk is closed and flushed to the OS every `FLUSH_TICKS` of simulated time,
so after SIGKILL the file is readable up to the last whole chunk.

Cost: the recorder is never on the lockstep's critical path (nobody waits for
it), so it runs at a lower CPU priority (`NICE`) and catches up in the gaps
the lockstep leaves; its work per message is one call into foxglove-sdk's
Rust MCAP writer.
"""

from __future__ import annotations

import bisect
import functools
import importlib.metadata
import os
import platform
import signal
import subprocess
import threading
from pathlib import Path

import msgspec

from arena.config import TEAMS, ConfigError
from arena.recording import scene
from arena.runtime.node import Observer
from arena.schemas.keys import KEYS, routes, spec_of
from arena.schemas.messages import EngineEvents, Referee, Summary, TapBatch, World

FORMAT = "1"  # version of the layout described in docs/recording.md
POLL_S = 0.02  # [s] wall: idle pause between polls of the tap and summary channels
GONE_GRACE_S = 2.0  # [s] wall: after a peer's liveliness token vanished, wait this long for its last data
FLUSH_TICKS = 50  # [ticks] close a chunk and flush it to the OS every second of simulated time
CHUNK_SIZE = 1 << 20  # [bytes] upper bound of one uncompressed chunk (FLUSH_TICKS usually comes first)
SCENE_HZ = 25.0  # [Hz] scene updates, at most one per world frame
NICE = 19  # [-] added niceness (Linux): the lockstep processes come first when the cores are busy
VERSIONED = ("soccer-arena", "eclipse-zenoh", "msgspec", "mcap", "foxglove-sdk", "pymunk", "numpy")
NEVER = 1 << 62  # [ticks] watermark of a process that has sent its final batch


class _Role(msgspec.Struct):
    """The one field of an `Order` the scene labels need (decoding the rest is wasted)."""

    role: str = ""


def data_topics(cfg) -> list[tuple[str, object]]:
    """(topic, KeySpec) for every data key of this match, in KEYS order."""
    out = []
    for spec in KEYS:
        if spec.sender == "refbox" and not cfg.refbox.listen:
            continue  # only a match with the RefBox bridge has worldstates
        teams = TEAMS if "<team>" in spec.pattern else ("",)
        numbers = range(cfg.robots) if "<n>" in spec.pattern else (None,)
        out.extend((spec.rel(t, n), spec) for t in teams for n in numbers)
    return out


def git_revision() -> str:
    """`git rev-parse HEAD` of the installed package's checkout, `-dirty` if tracked files
    differ from it; best effort: `unknown` outside a checkout or without git."""
    here = Path(__file__).resolve().parent

    def git(*args: str) -> subprocess.CompletedProcess | None:
        try:
            return subprocess.run(["git", *args], cwd=here, capture_output=True, text=True, timeout=5)
        except (OSError, subprocess.SubprocessError):
            return None

    head = git("rev-parse", "HEAD")
    if head is None or head.returncode != 0 or not head.stdout.strip():
        return "unknown"
    dirty = git("diff", "--quiet", "HEAD")
    return head.stdout.strip() + ("-dirty" if dirty is not None and dirty.returncode == 1 else "")


def versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for name in VERSIONED:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


class McapSink:
    """foxglove-sdk's MCAP writer (Rust) with this project's channels; counts messages per topic.

    The writer is the SDK's, not ours: measured on a real match's messages it
    costs no more CPU per message than the hand-written one it replaced, gives
    the same bytes for the same messages, and is one library call per message
    (docs/performance.md, "MCAP writer"). Every channel has the file's own
    writer context, so nothing else in this process (a viewer) sees it.
    Sequence numbers count from 1 per channel; publish time = log time.
    """

    def __init__(self, path: str, cfg):
        import foxglove
        from foxglove.mcap import MCAPWriteOptions

        self._ctx = foxglove.Context()
        # compression_threads=0: zstd on this (niced) thread, not one thread per core beside the lockstep.
        opts = MCAPWriteOptions(chunk_size=CHUNK_SIZE, compression_threads=0)
        self.writer = foxglove.open_mcap(path, allow_overwrite=True, context=self._ctx, writer_options=opts)
        self.channels: dict[str, object] = {}  # topic -> the channel's `log(payload, log_time)`
        self.counts: dict[str, int] = {}  # messages per topic
        self.types: dict[str, type] = {}  # schema name -> message type
        for topic, spec in data_topics(cfg):
            self._channel(
                topic,
                "msgpack",
                foxglove.Schema(name=spec.message.__name__, encoding="", data=b""),
                {
                    "data_pair": spec.data_pair,
                    "sender": spec.sender,
                    "receivers": spec.receivers,
                    "link_class": spec.link_class,
                },
            )
            self.types[spec.message.__name__] = spec.message
        for topic in (scene.SCENE_TOPIC, scene.LOG_TOPIC):
            s = scene.schema(topic)
            self._channel(topic, "protobuf", foxglove.Schema(name=s.name, encoding=s.encoding, data=s.data))

    def _channel(self, topic: str, encoding: str, schema, metadata: dict[str, str] | None = None):
        import foxglove

        ch = foxglove.Channel(topic, schema=schema, message_encoding=encoding, context=self._ctx, metadata=metadata)
        self.channels[topic] = log = ch.base.log
        self.counts[topic] = 0
        return log

    def add(self, topic: str, ns: int, payload: bytes) -> None:
        log = self.channels.get(topic)
        if log is None:  # a key this match's configuration does not know: keep it anyway
            log = self._channel(topic, "msgpack", None)
        self.counts[topic] += 1
        log(payload, ns)

    def metadata(self, name: str, data: dict[str, str]) -> None:
        self.writer.write_metadata(name, data)

    def flush(self) -> None:
        self.writer.flush()

    def finish(self) -> None:
        self.writer.close()


class RecorderNode(Observer):
    """`path`: the MCAP file to write. Only the recorder gets it; the others see `cfg.tap`."""

    def __init__(self, *args, path: str = "", **kwargs):
        super().__init__(*args, **kwargs)
        cfg = self.cfg
        if not cfg.tap:
            raise ConfigError("this match does not record: start it with --record FILE.mcap")
        if not path:
            raise ConfigError("the recorder needs --record FILE.mcap")
        self.path = path
        self.peers = [str(p) for p in cfg.processes() if p.kind not in ("recorder", "viewer")]
        self.rank = {name: i for i, name in enumerate(self.peers)}
        # One subscription per process, so that each batch and summary is checked
        # against its owner's MAC key (runtime/mac.py) and its owner's keys.
        self.tap_in = {name: self._owned(self.keys.tap(name), name) for name in self.peers}
        self.summary_in = {name: self._owned(self.keys.summary(name), name) for name in self.peers}
        self.owns = {name: set() for name in self.peers}  # keys each process may send (the key table)
        for rel, sender, _ in routes(cfg.robots):
            if sender in self.owns:
                self.owns[sender].add(rel)
        # key -> decoder of its message type: a frame that does not decode is not written
        decoders = {spec.name: msgspec.msgpack.Decoder(spec.message).decode for spec in KEYS}
        self._decode_as = {rel: decoders[spec_of(rel).name] for owned in self.owns.values() for rel in owned}
        self._decode_batch = msgspec.msgpack.Decoder(TapBatch).decode
        self._decode_summary = msgspec.msgpack.Decoder(Summary).decode
        self._decode_world = msgspec.msgpack.Decoder(World).decode
        self._decode_referee = msgspec.msgpack.Decoder(Referee).decode
        self._decode_events = msgspec.msgpack.Decoder(EngineEvents).decode
        self._decode_role = msgspec.msgpack.Decoder(_Role).decode
        self.water = dict.fromkeys(self.peers, 0)  # per process: no frame below this tick will come
        self.sent = dict.fromkeys(self.peers, 0)  # per process: frames received so far (send order)
        self.batches = dict.fromkeys(self.peers, 0)  # per process: next expected batch number
        self.finals: set[str] = set()
        self.lost_batches: dict[str, list[list[int]]] = {}  # per process: [first, last] batch numbers never received
        self.recorded: dict[str, dict[str, int]] = {name: {} for name in self.peers}  # per process and key
        self.summaries: dict[str, Summary] = {}
        self.pending: list[tuple[int, int, int, str, bytes]] = []  # (tick, rank, seq, topic, payload)
        self.missing: list[str] = []
        self.gap_list: dict[str, dict] = {}
        self.interrupted = ""
        self.sink: McapSink | None = None
        self.counts: dict[str, int] = {}  # messages written per topic
        self.scene = scene.SceneBuilder(cfg)
        dt = cfg.timing.dt
        self._dt_ns = dt * 1e9
        self._scene_every = max(1, round(1.0 / (SCENE_HZ * dt)))  # [ticks]
        self._next_scene = 0
        self._next_flush = FLUSH_TICKS
        self._gone_since: dict[str, float] = {}
        self._derive = self._derivations()
        # The file is created before the start barrier: a path that cannot be
        # written stops this process before anybody plays.
        try:
            self._open()
        except OSError as exc:
            raise ConfigError(f"cannot write --record {self.path}: {exc.strerror or exc}") from None

    # ------------------------------------------------------------------ file
    def _open(self) -> None:
        cfg = self.cfg
        version = versions()
        self.sink = McapSink(self.path, cfg)
        self.counts = self.sink.counts
        self.sink.metadata(
            "arena",
            {
                "format": FORMAT,
                "config": cfg.to_json(),
                "seed": str(cfg.seed),
                "home": cfg.home,
                "away": cfg.away,
                "robots": str(cfg.robots),
                "half_time": repr(cfg.half_time),
                "link": cfg.link,
                "realtime": str(cfg.realtime).lower(),
                "dt": repr(cfg.timing.dt),
                "match": self.keys.match,
                "processes": msgspec.json.encode(self.peers).decode(),
                "git_revision": git_revision(),
            },
        )
        self.sink.metadata("versions", version)
        self.sink.metadata(
            "schemas",
            {name: msgspec.json.encode(msgspec.json.schema(t)).decode() for name, t in self.sink.types.items()},
        )
        self.sink.flush()

    def gaps(self) -> dict[str, dict]:
        """What the file lacks, per process: tap batches never received, and per key the frames
        its Summary says it sent against those recorded (only keys that differ)."""
        out: dict[str, dict] = {}
        for name in self.peers:
            gap: dict = {}
            if name in self.lost_batches:
                gap["lost_batches"] = self.lost_batches[name]
            s = self.summaries.get(name)
            if s is None:
                gap["summary"] = "none received: its counts cannot be checked"
            else:
                got = self.recorded[name]
                keys = {
                    k: {"sent": n, "recorded": got.get(k, 0)}
                    for k, n in sorted(s.sent_by_key.items())
                    if got.get(k, 0) != n
                }
                if keys:
                    gap["keys"] = keys
            if gap:
                out[name] = gap
        return out

    def _close(self) -> None:
        if self.sink is None:
            return
        self.missing = [n for n in self.peers if n not in self.finals]
        self.gap_list = self.gaps()
        for name in self.peers:
            s = self.summaries.get(name)
            if s is not None:
                self.sink.metadata(f"summary/{name}", {"json": msgspec.json.encode(s).decode()})
        self.sink.metadata(
            "recording",
            {
                "complete": str(self.complete).lower(),
                "missing": ",".join(self.missing),
                "gaps": msgspec.json.encode(self.gap_list).decode(),
                "interrupted": self.interrupted,
                "last_tick": str(self.last_tick),
            },
        )
        self.sink.finish()
        self.sink = None

    # ----------------------------------------------------------------- intake
    def _owned(self, key: str, owner: str):
        verify = self.keyring.verifier(owner, key)
        on_forged = functools.partial(self.rejections.reject, key, "forged", f"not from {owner}")
        return self.transport.subscribe(key, verify=verify, on_forged=on_forged)

    def _frames(self, owner: str, frames):
        """The frames of `owner`'s batch that it may send and that decode as their key's type."""
        owns, decoders = self.owns[owner], self._decode_as
        for f in frames:
            if f.key not in owns:
                self.rejections.reject(self.keys.tap(owner), "forged", f"{owner} does not send {f.key!r}")
                continue
            try:
                decoders[f.key](f.payload)
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self.rejections.reject(self.keys.tap(owner), "malformed", f"{f.key}: {str(exc)[:100]}")
                continue
            yield f

    def _on_batch(self, raw: bytes, owner: str) -> None:
        try:
            batch = self._decode_batch(raw)
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            self.rejections.reject(self.keys.tap(owner), "malformed", str(exc)[:120])
            return
        name = batch.process
        rank = self.rank.get(name)
        if name != owner or rank is None:
            self.rejections.reject(self.keys.tap(owner), "forged", f"a batch of {name!r} on {owner}'s tap")
            return
        if batch.seq != self.batches[name]:
            self.rejections.reject(
                self.keys.tap(name), "out-of-sequence", f"batch {batch.seq}, expected {self.batches[name]}"
            )
            if batch.seq > self.batches[name]:
                self.lost_batches.setdefault(name, []).append([self.batches[name], batch.seq - 1])
        self.batches[name] = batch.seq + 1
        seq = self.sent[name]
        counts = self.recorded[name]
        for f in self._frames(name, batch.frames):
            self.pending.append((f.tick, rank, seq, f.key, f.payload))
            counts[f.key] = counts.get(f.key, 0) + 1
            seq += 1
        self.sent[name] = seq
        if batch.final:
            self.finals.add(name)
            self.water[name] = NEVER
        else:
            self.water[name] = max(self.water[name], batch.tick)

    def _on_summary(self, raw: bytes, owner: str) -> None:
        try:
            s = self._decode_summary(raw)
        except (msgspec.DecodeError, msgspec.ValidationError):
            return  # not ours to judge: the collector reports it
        if s.process == owner:
            self.summaries.setdefault(s.process, s)

    def _drain(self) -> bool:
        got = False
        for name, channel in self.tap_in.items():
            while (raw := channel.try_recv()) is not None:
                self._on_batch(raw, name)
                got = True
        for name, channel in self.summary_in.items():
            while (raw := channel.try_recv()) is not None:
                self._on_summary(raw, name)
                got = True
        if got:
            self._write_ready(min(self.water.values()))
        return got

    def _finished(self) -> bool:
        """Has every peer sent its last batch and its summary, or been gone for GONE_GRACE_S?

        Every peer is looked at on every poll, so that a peer's grace runs from when its token
        vanished, not from when every peer before it in the list had finished."""
        now = self.clock.monotonic()
        done = True
        for name in self.peers:
            gone = name in self.gone
            if gone:
                since = self._gone_since.setdefault(name, now)
            else:
                self._gone_since.pop(name, None)  # back (a stopped process that resumed), or never gone
            if name in self.finals and name in self.summaries:
                continue
            if gone and (name in self.summaries or now - since >= GONE_GRACE_S):
                continue
            done = False
        return done

    # ----------------------------------------------------------------- output
    def _write_ready(self, watermark: int) -> None:
        """Write every pending frame with a tick below `watermark`, in (tick, process, send) order."""
        pending = self.pending
        pending.sort()
        cut = bisect.bisect_left(pending, watermark, key=lambda r: r[0])
        if cut == 0:
            return
        ready, self.pending = pending[:cut], pending[cut:]
        for tick, _, _, topic, payload in ready:
            self._write(tick, topic, payload)

    def _write(self, tick: int, topic: str, payload: bytes) -> None:
        if tick >= self._next_flush:
            self.sink.flush()
            self._next_flush = tick - tick % FLUSH_TICKS + FLUSH_TICKS
        ns = round(tick * self._dt_ns)
        self.sink.add(topic, ns, payload)
        if tick > self.last_tick:
            self.last_tick = tick
        derive = self._derive.get(topic)
        if derive is not None:
            try:
                derive(tick, ns, payload)
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self.rejections.reject(topic, "malformed", str(exc)[:120])

    # The Foxglove layer, derived from the frames as they are written.
    def _derivations(self) -> dict[str, object]:
        out: dict[str, object] = {
            "world": self._scene_frame,
            "referee": self._referee_log,
            "engine/events": self._events_log,
        }
        for team in TEAMS:
            for n in range(self.cfg.robots):
                out[f"team/{team}/order/{n}"] = self._role_of(team, n)
        return out

    def _scene_frame(self, tick: int, ns: int, payload: bytes) -> None:
        if tick >= self._next_scene:
            self._next_scene = tick + self._scene_every
            self.sink.add(scene.SCENE_TOPIC, ns, self.scene.update(self._decode_world(payload), ns))

    def _referee_log(self, tick: int, ns: int, payload: bytes) -> None:
        for log in self.scene.referee_log(self._decode_referee(payload), ns):
            self.sink.add(scene.LOG_TOPIC, ns, log)

    def _events_log(self, tick: int, ns: int, payload: bytes) -> None:
        for log in self.scene.events_log(self._decode_events(payload), ns):
            self.sink.add(scene.LOG_TOPIC, ns, log)

    def _role_of(self, team: str, n: int):
        def role(tick: int, ns: int, payload: bytes) -> None:
            self.scene.roles[(team, n)] = self._decode_role(payload).role

        return role

    # ------------------------------------------------------------------- loop
    def _on_signal(self, stop: threading.Event):
        def handler(signum, frame):
            self.interrupted = signal.Signals(signum).name
            stop.set()

        return handler

    def observe(self) -> None:
        stop = threading.Event()
        previous = {}
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGTERM, signal.SIGINT):
                previous[sig] = signal.signal(sig, self._on_signal(stop))
            os.nice(NICE)  # a process of its own (arena run recorder); never a test's thread
        try:
            silent_since = self.clock.monotonic()
            while not self._finished() and not stop.is_set():
                if self._drain():
                    silent_since = self.clock.monotonic()
                    continue
                if self.clock.monotonic() - silent_since > self.cfg.timing.wait_timeout:
                    self.log.error("no tap batch for %g s: closing the recording", self.cfg.timing.wait_timeout)
                    break
                self.clock.sleep(POLL_S)
        finally:
            self.finish()
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        if self.interrupted:
            raise SystemExit(128 + signal.Signals[self.interrupted].value)

    # A cooperative match (match/inprocess.py) calls these two instead of `observe`.
    def pump(self) -> None:
        """Take in the tap batches and summaries that are there; write what every watermark passed."""
        self._drain()

    def finish(self) -> None:
        """Take in the rest, write every pending frame, close the file."""
        try:
            self._drain()
            self._write_ready(NEVER)
        finally:
            self._close()

    @property
    def complete(self) -> bool:
        """Every process's last batch came, no batch was lost, and every count equals its sender's Summary."""
        return not self.missing and not self.interrupted and not self.gap_list

    def summary_extra(self) -> dict[str, object]:
        return {
            "path": self.path,
            "messages": dict(sorted(self.counts.items())),
            "complete": self.complete,
            "missing": self.missing,
            "gaps": self.gap_list,
        }
