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
digest differs is refused (tools/launcher.py `supervise`).
"""

from __future__ import annotations

import hashlib
import threading

import msgspec

from arena.runtime.lockstep import BATCH_HEADS, MAX_BATCH, decode_batch
from arena.schemas.keys import Keys, routes, spec_of


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
        for rel, sender, _ in routes(robots):
            if sender in self.digests:
                spec = spec_of(rel)
                if spec is not None and spec.timing.period is not None:
                    transport.subscribe_callback(keys.prefix + rel, self._on(sender, rel, spec, periods))

    def _on(self, sender: str, rel: str, spec, periods: dict[str, int]):
        """Only the in-sequence frame of each scheduled tick counts, as for a receiver.

        Anyone can put on an external's keys (outside --secure): garbage, or frames
        for ticks it has not reached, never enter the recomputed digest; a second
        frame for a tick already counted makes the digest unverifiable, not wrong.
        """
        h = self.digests[sender]
        period, phase = spec.timing.schedule(periods)
        decode = msgspec.msgpack.Decoder(spec.message).decode
        due = [phase]

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
                    digest_update(h, rel, payload)
                    self.frames[sender] += 1
                    due[0] += period
                elif tick < due[0]:
                    self.conflicted.add(sender)

        return on_frame

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
