"""The launcher's check of an external process's Summary digest.

A process's digest is BLAKE2b (16 bytes) over every frame it sent, in send
order: for each frame the key without the `arena/<match>/` prefix (UTF-8),
the payload's length (4 bytes, little-endian) and the payload
(runtime/lockstep.py `Outbound.send`). The launcher's own children are its
code; an `--external` process is not, so for each one the launcher (the
match's router) subscribes to every data key that process sends and
recomputes the digest from the frames as they arrive. zenoh keeps one
session's puts in order, and the frames come before the Summary, so by the
time its Summary arrives the witness has seen all of them: a Summary whose
digest differs is refused (match/supervise.py `supervise`).

Send order is not quite wire order. In lockstep a robot holds its `cmd`
frames, and the engine its `sense` frames, for up to L ticks and puts them as
one batch (runtime/lockstep.py `Outbound.batch`), while every other key's
frame is put as it is sent: a robot's `report` of tick k reaches the wire
before the `cmd` of tick k that it sent first. So the witness puts the frames
back in send order: by tick; within a tick the batched keys first, in the
order of the key table (the engine's senses robot by robot, as it sends
them), then the others in the order they came. A frame is added to the
digest once no batched frame that was sent before it can still arrive.
"""

from __future__ import annotations

import hashlib
import heapq
import threading

import msgspec

from arena.runtime.lockstep import BATCH_HEADS, MAX_BATCH, decode_batch
from arena.schemas.keys import Keys, routes, spec_of

# The keys whose frames a sender may hold back and put as a batch (processes/engine.py, processes/robot.py).
BATCHED = frozenset({"sense", "cmd"})


def digest_update(h: hashlib.blake2b, rel: str, payload: bytes) -> None:
    """Add one sent frame to a process digest (the contract: schemas/README.md)."""
    h.update(rel.encode())
    h.update(len(payload).to_bytes(4, "little"))
    h.update(payload)


class Witness:
    """Recomputes the digest of each watched process from the frames it puts."""

    def __init__(self, transport, keys: Keys, robots: int, watched: set[str], periods: dict[str, int]):
        self.digests: dict[str, hashlib.blake2b] = {name: hashlib.blake2b(digest_size=16) for name in watched}
        self.frames: dict[str, int] = dict.fromkeys(watched, 0)
        self.matched: set[str] = set()
        self.conflicted: set[str] = set()  # someone else put a frame for a tick it had sent
        self._lock = threading.Lock()
        # Per sender: accepted frames not yet in the digest, a heap of (tick, 0, rank, seq, rel, payload)
        # for a batched key or (tick, 1, seq, 0, rel, payload) for another; and, per batched key, the
        # (tick, 0, rank) of its next frame due, which no frame after it in send order may overtake.
        self._held: dict[str, list] = {name: [] for name in watched}
        self._next: dict[str, dict[str, tuple[int, int, int]]] = {name: {} for name in watched}
        self._seq = 0
        # Only frames with the sender's MAC count (runtime/mac.py): a stranger's frame for a tick the
        # external has not sent yet would otherwise enter the digest and refuse its genuine Summary.
        ring = getattr(transport, "keyring", None)
        for rank, (rel, sender, _) in enumerate(routes(robots)):
            if sender in self.digests:
                spec = spec_of(rel)
                if spec is not None and spec.timing.period is not None:
                    verify = ring.verifier(sender, keys.prefix + rel) if ring is not None else None
                    on_frame = self._on(sender, rel, spec, periods, rank)
                    transport.subscribe_callback(keys.prefix + rel, on_frame, verify)

    def _on(self, sender: str, rel: str, spec, periods: dict[str, int], rank: int):
        """Only the in-sequence frame of each scheduled tick counts, as for a receiver.

        Anyone can put on an external's keys (outside --secure): garbage, or frames
        for ticks it has not reached, never enter the recomputed digest; a second
        frame for a tick already counted makes the digest unverifiable, not wrong.
        """
        period, phase = spec.timing.schedule(periods)
        decode = msgspec.msgpack.Decoder(spec.message).decode
        due = [phase]
        batched = spec.name in BATCHED
        held, nxt = self._held[sender], self._next[sender]
        if batched:
            nxt[rel] = (phase, 0, rank)

        def on_frame(payload: bytes) -> None:
            if payload[:1] == b"\xc1":  # a local wake-up, never a message
                return
            if payload[:1] and payload[0] in BATCH_HEADS:  # several ticks' frames in one message (`Outbound.batch`)
                try:
                    frames = decode_batch(payload)
                except (msgspec.DecodeError, msgspec.ValidationError):
                    return
                for frame in frames if len(frames) <= MAX_BATCH else ():
                    one(frame)
            else:
                one(payload)

        def one(payload: bytes) -> None:
            try:
                tick = decode(payload).tick
            except (msgspec.DecodeError, msgspec.ValidationError):
                return
            with self._lock:
                if tick == due[0]:
                    self._seq += 1
                    order = (tick, 0, rank, self._seq) if batched else (tick, 1, self._seq, 0)
                    heapq.heappush(held, (*order, rel, payload))
                    self.frames[sender] += 1
                    due[0] += period
                    if batched:
                        nxt[rel] = (due[0], 0, rank)
                    self._fold(sender, everything=False)
                elif tick < due[0]:
                    self.conflicted.add(sender)

        return on_frame

    def _fold(self, sender: str, everything: bool) -> None:
        """Add `sender`'s held frames to its digest, in send order, as far as none sent earlier can still come."""
        held, h = self._held[sender], self.digests[sender]
        first_missing = min(self._next[sender].values(), default=None)
        while held and (everything or first_missing is None or held[0][:3] < first_missing):
            *_, rel, payload = heapq.heappop(held)
            digest_update(h, rel, payload)

    def check(self, name: str, digest: str, dead: list[str]) -> str | None:
        """None if `digest` is what `name` sent; otherwise why not.

        A process that lost a receiver (`dead` not empty) stops putting the keys
        only that receiver reads while its digest goes on (runtime/lockstep.py
        `Outbound.mute`): its digest cannot be recomputed from the wire, so it is
        accepted unverified rather than refused.
        """
        if name not in self.digests:
            return None
        with self._lock:
            self._fold(name, everything=True)  # its Summary came after every frame it put
            seen = self.digests[name].hexdigest()
            n = self.frames[name]
        if seen == digest:
            self.matched.add(name)
        elif not dead and name not in self.conflicted:
            return f"digest {digest} is not that of the {n} frames it sent ({seen})"
        return None

    def verified(self) -> list[str]:
        """The watched processes whose digest was recomputed and matched."""
        return sorted(self.matched)
