"""Taps: what a process sent, batched for the recorder (docs/recording.md).

A recorder that subscribed to every key of a match would receive every frame
a second time, which would roughly halve the match's speed on 2 cores
(docs/performance.md, "Measurements behind design choices"). Instead, when the match records, every process keeps a copy of
what it sends (a list append per frame) and publishes it as ONE `TapBatch`
every `TAP_PERIOD` ticks on `arena/<m>/tap/<process>`, plus a final batch at
the end of the match, before its `Summary`.

Batches are cut on tick boundaries (multiples of `TAP_PERIOD`), so their
content is a pure function of the match; only when they arrive depends on the
machine. A batch's `tick` is a watermark: the process will send no frame with a
lower tick, so the recorder can write frames in a deterministic order.

When the match does not record there is no tap and `Outbound` is the plain
class: not one instruction is added to its `send`.
"""

from __future__ import annotations

import hashlib
import queue
import threading
from collections.abc import Callable
from typing import Any

from arena.runtime.lockstep import Outbound
from arena.schemas.keys import TAP_PERIOD
from arena.schemas.messages import TapBatch, TapFrame, encode


class Tap:
    """The process's tap buffer: frames in send order, cut every `period` ticks."""

    def __init__(self, process: str, put: Callable[[bytes], None], period: int = TAP_PERIOD):
        self.process = process
        self._put = put
        self.period = period
        self._frames: list[tuple[str, int, bytes]] = []
        self._boundary = period  # the first frame at or past this tick cuts a batch
        self._seq = 0
        self.closed = False

    def add(self, key: str, tick: int, payload: bytes) -> None:
        if tick >= self._boundary:
            self.advance(tick)
        self._frames.append((key, tick, payload))

    def advance(self, tick: int) -> None:
        """Time has come to `tick`: cut the batch as a frame at `tick` would, so the
        recorder's watermark moves on for a process that sends rarely (the RefBox bridge)."""
        if tick >= self._boundary:
            start = tick - tick % self.period
            self._publish(start, final=False)
            self._boundary = start + self.period

    def close(self, last_tick: int) -> None:
        """The final batch: everything not yet published (call before the Summary)."""
        if not self.closed:
            last = max([last_tick] + [t for _, t, _ in self._frames])
            self._publish(last + 1, final=True)
            self.closed = True

    def _publish(self, watermark: int, final: bool) -> None:
        frames = [TapFrame(key=k, tick=t, payload=p) for k, t, p in self._frames]
        self._frames = []
        self._put(encode(TapBatch(tick=watermark, process=self.process, seq=self._seq, final=final, frames=frames)))
        self._seq += 1


class Handoff:
    """A put that happens on a thread of its own, in order.

    A reactive node (runtime/drivers.py, `Reactor`) runs on zenoh's only
    network thread. A tap batch is large (up to ~100 kB for the engine): a
    blocking put that needs more room than the transmit queue has would wait
    for the transmit task, which runs on that same thread. So batches leave
    from here instead; `close` waits until every one is out.
    """

    def __init__(self, put: Callable[[bytes], None]):
        self._put = put
        self._queue: queue.SimpleQueue[bytes | None] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="tap", daemon=True)
        self._thread.start()

    def __call__(self, payload: bytes) -> None:
        self._queue.put(payload)

    def _run(self) -> None:
        while (payload := self._queue.get()) is not None:
            self._put(payload)

    def close(self) -> None:
        self._queue.put(None)
        self._thread.join()


class TappedOutbound(Outbound[Any]):
    """An `Outbound` that also hands every frame to the process's tap."""

    __slots__ = ("_tap", "_rel_str")

    def __init__(self, key: str, rel: str, put: Callable[[bytes], None], digest: hashlib.blake2b, tap: Tap):
        super().__init__(key, rel, put, digest)
        self._tap = tap
        self._rel_str = rel

    def send(self, msg: Any) -> bytes:
        payload = Outbound.send(self, msg)
        self._tap.add(self._rel_str, msg.tick, payload)
        return payload
