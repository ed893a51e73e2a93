"""`arena bench mcap FILE.mcap`: our MCAP writer against foxglove-sdk's, on a real match.

Reads every message of a recording (topic, log time, payload) into memory, then
writes them all again, `--repeat` times, with one writer:

* `ours`: recording/writer.py, as the recorder uses it (zstd level 3, 1 MiB
  chunks, one schema-less msgpack channel per topic);
* `foxglove`: the SDK's Rust writer, `foxglove.open_mcap` with one msgpack
  channel per topic and `ch.base.log(payload, log_time)`, zstd, 1 MiB chunks,
  `compression_threads=0` (no zstd threads competing with a match).

Prints the median CPU time and wall time per message [us] over the repeats
(CPU time: `time.process_time`, which on a loaded machine moves far less than
the wall clock), the file size, and
whether two writes of the same messages gave the same bytes. Only the writing
is timed; reading the input is not.
"""

from __future__ import annotations

import hashlib
import json
import statistics
import tempfile
import time
from pathlib import Path

from arena.runtime.config import ConfigError

WRITERS = ("ours", "foxglove")
CHUNK = 1 << 20  # [bytes] the recorder's chunk size


def read_messages(path: str) -> list[tuple[str, int, bytes]]:
    """(topic, log time [ns], payload) of every message of `path`, in file order."""
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as f:
            return [(ch.topic, m.log_time, m.data) for _, ch, m in make_reader(f).iter_messages(log_time_order=False)]
    except OSError as exc:
        raise ConfigError(f"cannot read {path}: {exc.strerror}") from None
    except Exception as exc:  # the mcap reader's own errors: not an MCAP file
        raise ConfigError(f"{path} is not a readable MCAP file: {exc}") from None


def write_ours(messages: list[tuple[str, int, bytes]], out: Path) -> None:
    from arena.recording.writer import McapWriter

    with open(out, "wb") as f:
        w = McapWriter(f, chunk_size=CHUNK)
        sid = w.register_schema(name="msgpack", encoding="", data=b"")
        channels: dict[str, int] = {}
        seq: dict[str, int] = {}
        for topic, ns, data in messages:
            ch = channels.get(topic)
            if ch is None:
                ch = channels[topic] = w.register_channel(topic=topic, message_encoding="msgpack", schema_id=sid)
            seq[topic] = seq.get(topic, 0) + 1
            w.add_message(ch, ns, data, ns, seq[topic])
        w.finish()


def write_foxglove(messages: list[tuple[str, int, bytes]], out: Path) -> None:
    import foxglove
    from foxglove.mcap import MCAPWriteOptions

    ctx = foxglove.Context()
    opts = MCAPWriteOptions(chunk_size=CHUNK, compression_threads=0)
    writer = foxglove.open_mcap(str(out), allow_overwrite=True, context=ctx, writer_options=opts)
    schema = foxglove.Schema(name="msgpack", encoding="", data=b"")
    channels: dict[str, object] = {}
    for topic, ns, data in messages:
        ch = channels.get(topic)
        if ch is None:
            ch = channels[topic] = foxglove.Channel(topic, context=ctx, message_encoding="msgpack", schema=schema).base
        ch.log(data, ns)  # type: ignore[attr-defined]
    writer.close()


def main(path: str, writer: str = "ours", repeat: int = 5, as_json: bool = False) -> int:
    if writer not in WRITERS:
        raise ConfigError(f"--writer {writer!r}: use {' or '.join(WRITERS)}")
    if repeat < 1:
        raise ConfigError(f"--repeat must be at least 1, got {repeat}")
    messages = read_messages(path)
    if not messages:
        raise ConfigError(f"{path} holds no messages")
    write = write_ours if writer == "ours" else write_foxglove
    wall, cpu, digests, size = [], [], set(), 0
    with tempfile.TemporaryDirectory(prefix="arena-mcapbench-") as tmp:
        for i in range(repeat):
            out = Path(tmp) / f"w{i}.mcap"
            w0, c0 = time.perf_counter(), time.process_time()
            write(messages, out)
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - w0)
            data = out.read_bytes()
            size = len(data)
            digests.add(hashlib.blake2b(data, digest_size=16).hexdigest())
            out.unlink()
    us = 1e6 * statistics.median(wall) / len(messages)
    cpu_us = 1e6 * statistics.median(cpu) / len(messages)
    result = {
        "writer": writer,
        "messages": len(messages),
        "repeat": repeat,
        "cpu_us_per_message_median": round(cpu_us, 3),
        "wall_us_per_message_median": round(us, 3),
        "bytes": size,
        "same_bytes_every_time": len(digests) == 1,
    }
    if as_json:
        print(json.dumps(result, indent=2))
    else:
        print(
            f"{writer}: {cpu_us:.2f} us CPU, {us:.2f} us wall per message (median of {repeat} writes of "
            f"{len(messages)} messages), "
            f"{size} bytes, same bytes every time: {len(digests) == 1}"
        )
    return 0
