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

from arena.schemas.keys import Keys, routes


def digest_update(h: hashlib.blake2b, rel: str, payload: bytes) -> None:
    """Add one sent frame to a process digest (the contract: schemas/README.md)."""
    h.update(rel.encode())
    h.update(len(payload).to_bytes(4, "little"))
    h.update(payload)


class Witness:
    """Recomputes the digest of each watched process from the frames it puts."""

    def __init__(self, transport, keys: Keys, robots: int, watched: set[str]):
        self.digests: dict[str, hashlib.blake2b] = {name: hashlib.blake2b(digest_size=16) for name in watched}
        self.frames: dict[str, int] = dict.fromkeys(watched, 0)
        self.matched: set[str] = set()
        self._lock = threading.Lock()
        for rel, sender, _ in routes(robots):
            if sender in self.digests:
                transport.subscribe_callback(keys.prefix + rel, self._on(sender, rel))

    def _on(self, sender: str, rel: str):
        h = self.digests[sender]

        def on_frame(payload: bytes) -> None:
            if payload[:1] == b"\xc1":  # a local wake-up, never a message
                return
            with self._lock:
                digest_update(h, rel, payload)
                self.frames[sender] += 1

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
        elif not dead:
            return f"digest {digest} is not that of the {n} frames it sent ({seen})"
        return None

    def verified(self) -> list[str]:
        """The watched processes whose digest was recomputed and matched."""
        return sorted(self.matched)
