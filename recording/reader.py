"""Reading a match recording back, tolerant of a truncated file (docs/recording.md).

`arena review` and `arena replay` both start here. The file is read
sequentially with the mcap library's stream reader, CRCs checked. A file the
recorder finished ends with a footer; a file cut short (the recorder was
SIGKILLed, the disk filled up) ends inside a record or a chunk: everything
before that point is kept and the recording is marked truncated, with the
reason. A file that is empty, not MCAP, or not written by our recorder is a
`RecordingError`, which the commands turn into one line and exit code 2.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path

import msgspec
import zstandard
from mcap.exceptions import InvalidMagic, McapError
from mcap.records import Channel, Footer, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from arena.config import ConfigError, MatchConfig
from arena.runtime.userfile import json_nesting
from arena.schemas.messages import Summary
from arena.schemas.validate import first_problem, nonfinite

# What a cut-off file can raise inside a record: short reads, a chunk that does
# not decompress, a CRC that does not match.
MAGIC = b"\x89MCAP0\r\n"  # the 8 bytes an MCAP file starts and ends with
_CUT = (McapError, struct.error, ValueError, EOFError, zstandard.ZstdError)


class RecordingError(ValueError):
    """Not a usable match recording; the message is one line."""


@dataclass
class Recording:
    path: str
    cfg: MatchConfig
    meta: dict[str, dict[str, str]]
    # topic -> [(log time [ns], sequence, payload)], in file order (the sender's order per key)
    topics: dict[str, list[tuple[int, int, bytes]]]
    schema_of: dict[str, str]  # topic -> schema name (the message type)
    counts: dict[str, int] = field(default_factory=dict)  # messages per topic, kept or not
    summaries: dict[str, Summary] = field(default_factory=dict)
    truncated: bool = False
    problem: str = ""  # why it is truncated
    undecodable: dict[str, int] = field(default_factory=dict)  # per topic: messages not of its type

    @property
    def complete(self) -> bool:
        """The recorder says it got every process's last batch, and the file is whole."""
        return not self.truncated and self.meta.get("recording", {}).get("complete") == "true"

    @property
    def interrupted(self) -> str:
        """The signal that stopped the match before its end ("SIGINT", "SIGTERM"), or ""."""
        return str(self.meta.get("recording", {}).get("interrupted", "") or "")

    @property
    def ends_early(self) -> str:
        """Why the file holds less than the whole match ("" if it holds it all): cut short, or stopped."""
        if self.truncated:
            return f"recording truncated ({self.problem})"
        return f"match stopped by {self.interrupted}" if self.interrupted else ""

    @property
    def gaps(self) -> dict:
        """What the recorder found missing, per process (lost tap batches, keys short of their count)."""
        try:
            gaps = msgspec.json.decode(self.meta.get("recording", {}).get("gaps", "{}"))
        except (msgspec.DecodeError, RecursionError):
            return {"?": {"error": "unreadable gaps metadata"}}
        return gaps if isinstance(gaps, dict) else {}

    def payloads(self, topic: str) -> list[bytes]:
        return [p for _, _, p in self.topics.get(topic, [])]

    def decoded(self, topic: str, msg_type: type):
        """The messages of `topic` that decode as `msg_type`; the others are skipped and counted
        in `undecodable` (a hostile or damaged file never ends a review in a traceback).

        A message that decodes but holds a number no match sends (a NaN, an infinity, or a
        magnitude over `MAX_MAGNITUDE`) is a RecordingError: the file was made, not recorded.
        """
        dec = msgspec.msgpack.Decoder(msg_type).decode
        out = []
        for _, _, p in self.topics.get(topic, []):
            try:
                msg = dec(p)
            except (msgspec.DecodeError, msgspec.ValidationError, RecursionError):  # nested past any message
                self.undecodable[topic] = self.undecodable.get(topic, 0) + 1
                continue
            problem = nonfinite(p, msg) or first_problem(msg, _too_large) or _too_deep(msg)
            if problem:
                raise RecordingError(
                    f"{self.path}: a {topic} frame (tick {msg.tick}) is not what a match sends: {problem}"
                )
            out.append(msg)
        return out


# [any unit] the largest number a review accepts in a decoded frame: positions are metres within a
# field's fence, speeds m/s, times s, ticks a few 100,000; 1e308 m overflowed the plots' pixels.
MAX_MAGNITUDE = 1e9


# [levels] the deepest JSON a frame may carry (a worldstate's text): the bridge records none deeper
# (rules/refbox_protocol.py MAX_DEPTH), and Python's JSON parser recurses once per level.
MAX_JSON_DEPTH = 32


def _too_deep(msg: object) -> str | None:
    text = getattr(msg, "json", None)
    if isinstance(text, str) and (depth := json_nesting(text)) > MAX_JSON_DEPTH:
        return f"its JSON nests {depth} levels deep, more than {MAX_JSON_DEPTH}"
    return None


def _too_large(value: object, path: str) -> str | None:
    if type(value) in (float, int) and abs(value) > MAX_MAGNITUDE:
        return f"{path or 'value'} = {value:g} is beyond {MAX_MAGNITUDE:g}"
    return None


def load(path: str, keep: frozenset[str] | set[str] | None = None) -> Recording:  # noqa: C901, PLR0912, PLR0915 - one pass over the file, every topic and damage counted where met
    """Read `path`; keep the messages of the topics in `keep` (all when None)."""
    p = Path(path)
    try:
        size = p.stat().st_size
        fh = open(p, "rb")
    except OSError as exc:
        raise RecordingError(f"cannot read {path}: {exc.strerror}") from None
    if size == 0:
        fh.close()
        raise RecordingError(f"{path} is empty")
    if fh.read(len(MAGIC)) != MAGIC:
        fh.close()
        raise RecordingError(f"{path} is not an MCAP file")
    fh.seek(0)
    meta: dict[str, dict[str, str]] = {}
    topics: dict[str, list[tuple[int, int, bytes]]] = {}
    counts: dict[str, int] = {}
    channels: dict[int, str] = {}
    schemas: dict[int, str] = {}
    schema_of: dict[str, str] = {}
    truncated, problem = True, "no footer"
    records = StreamReader(fh, validate_crcs=True).records
    try:
        for rec in records:
            if isinstance(rec, Message):
                topic = channels.get(rec.channel_id)
                if topic is not None:
                    counts[topic] += 1
                    if keep is None or topic in keep:
                        topics[topic].append((rec.log_time, rec.sequence, rec.data))
            elif isinstance(rec, Channel):
                if rec.id not in channels:
                    channels[rec.id] = rec.topic
                    topics.setdefault(rec.topic, [])
                    counts.setdefault(rec.topic, 0)
                    schema_of[rec.topic] = schemas.get(rec.schema_id, "")
            elif isinstance(rec, Schema):
                schemas[rec.id] = rec.name
            elif isinstance(rec, Metadata):
                meta[rec.name] = dict(rec.metadata)
            elif isinstance(rec, Footer):
                truncated, problem = False, ""
    except InvalidMagic:
        truncated, problem = True, "the file does not end with the MCAP magic"
    except _CUT:
        truncated, problem = True, "the file ends inside a record"
    finally:
        fh.close()
    if "arena" not in meta:
        if truncated:
            raise RecordingError(f"{path} is cut short before the match metadata: nothing to read")
        raise RecordingError(f"{path} is MCAP, but not an arena match recording (no 'arena' metadata)")
    try:
        cfg = MatchConfig.from_json(meta["arena"]["config"])
    except (ConfigError, KeyError) as exc:
        raise RecordingError(f"{path}: unusable match configuration: {exc}") from None
    summaries = {}
    dec = msgspec.json.Decoder(Summary).decode
    for name, data in meta.items():
        if name.startswith("summary/") and "json" in data:
            try:
                s = dec(data["json"])
            except (msgspec.DecodeError, msgspec.ValidationError, RecursionError):
                continue
            summaries[s.process] = s
    if keep is not None:
        topics = {t: v for t, v in topics.items() if t in keep}
    return Recording(str(p), cfg, meta, topics, schema_of, counts, summaries, truncated, problem)
