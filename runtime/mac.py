"""Message authentication: who really sent an owned message (the inner wall).

zenoh tells a subscriber nothing it can trust about a sample's sender: the
source info is written by the sender itself, and without `--secure` anybody
who reaches the router can put on any key. So every frame of a match carries a
MAC, in the sample's zenoh attachment (the payload, and so every digest and
every recorded byte, stays exactly what it was):

    attachment = BLAKE2b(key=K_sender, digest_size=16)(key_expr || 0x00 || payload)

`key_expr` is the full key put on (`arena/<match>/engine/events`), `K_sender`
the sender's own 32-byte key. Every process of a match gets a fresh random key
from the launcher (in its credentials fragment, schemas/README.md "Security"),
and the keys of the senders of every key it receives (the key table's
`routes`): every data key (`sense`, `cmd`, `report`, `order`, `referee`,
`engine/events`, `world`, `field`, `worldstate`), every `tap/<p>` and
`summary/<p>`, and the keys outside the table: a live session's `operator`
(the operator's, which the engine and the referee verify) and `control` (the
viewer's, which the engine verifies), and the answers to queries (`config` and
`field` from the engine, the served `report`s and `order`s, the viewer's
`control` state), whose MAC rides in the reply's attachment. The collector
(`arena match`) and the recorder hold every key.

A receiver checks the MAC before the frame reaches its lockstep: one with a
missing or wrong MAC is dropped and counted, per key, as `forged`, so it can
never take a tick's slot, displace or delay the genuine frame. A process with
no key (started by hand without `--credentials`) sends no MAC, and a receiver
with no key for a sender accepts what comes: that is the match of earlier
versions, no worse. Replays of genuine messages are caught by what is already
there: ticks and batch numbers in sequence, one Summary per process.

A MAC is symmetric: a receiver that holds a sender's key could forge that
sender's frames to the others. Without `--secure` that is no new power (anyone
on the router can put on any key; the MAC keeps out whoever has no key); with
`--secure`, the router's access control lets a principal put only on the keys
it sends (runtime/acl.py).
"""

from __future__ import annotations

import hashlib
import hmac
import os
from collections.abc import Callable

from arena.schemas.keys import MAC_BYTES, MAC_KEY_BYTES

TAG_BYTES = MAC_BYTES
KEY_BYTES = MAC_KEY_BYTES


def new_key() -> bytes:
    return os.urandom(KEY_BYTES)


def _prefix(key: bytes, key_expr: str):
    """The BLAKE2b state after the key and `key_expr || 0x00`: the part of a tag that is the same
    for every frame on one key."""
    h = hashlib.blake2b(key=key, digest_size=TAG_BYTES)
    h.update(key_expr.encode())
    h.update(b"\0")
    return h


def tag(key: bytes, key_expr: str, payload: bytes) -> bytes:
    h = _prefix(key, key_expr)
    h.update(payload)
    return h.digest()


def _tagger(key: bytes, key_expr: str) -> Callable[[bytes], bytes]:
    """tag(key, key_expr, payload) for any payload: the keyed prefix is hashed once, then copied
    per frame (the same bytes as `tag`, at about half its cost). The prefix rides along as the
    function's `prefix`, for a caller that tags in its own loop (`copy_of`)."""
    prefix = _prefix(key, key_expr)

    def of(payload: bytes) -> bytes:
        h = prefix.copy()
        h.update(payload)
        return h.digest()

    of.prefix = prefix  # type: ignore[attr-defined]
    return of


def copy_of(mac: Callable) -> Callable[[], hashlib.blake2b] | None:
    """The keyed prefix's `copy` behind a signer or verifier of this module: a hot path (a zenoh
    callback, a put) tags a frame with `h = copy(); h.update(payload); h.digest()` in its own
    frame, the same bytes without two Python calls a frame. None for any other callable."""
    prefix = getattr(mac, "prefix", None)
    return None if prefix is None else prefix.copy


class Keyring:
    """This process's own key and the keys of the senders it verifies."""

    def __init__(self, process: str = "", keys: dict[str, bytes] | None = None):
        self.process = process
        self.keys = dict(keys or {})

    @classmethod
    def from_hex(cls, process: str, keys: dict[str, str]) -> Keyring:
        try:
            raw = {p: bytes.fromhex(k) for p, k in keys.items()}
        except (ValueError, TypeError, AttributeError):
            raise ValueError("credentials: a key is not hex") from None
        if any(len(k) != KEY_BYTES for k in raw.values()):
            raise ValueError(f"credentials: every key must be {KEY_BYTES} bytes")
        return cls(process, raw)

    @property
    def own(self) -> bytes | None:
        return self.keys.get(self.process)

    def signer(self, key_expr: str, sender: str | None = None) -> Callable[[bytes], bytes] | None:
        """attachment(payload) for a key this process sends, or None without a key.

        `sender`: sign as that principal, whose key this keyring holds (the live viewer forwards
        a local operator's Foxglove messages with the operator's key, processes/viewer.py)."""
        k = self.keys.get(self.process if sender is None else sender)
        if k is None:
            return None
        return _tagger(k, key_expr)

    def verifier(self, sender: str, key_expr: str) -> Callable[[bytes, bytes | None], bool] | None:
        """ok(payload, attachment) for frames of `sender` on `key_expr`; None: no key, accept all."""
        k = self.keys.get(sender)
        if k is None:
            return None
        expected = _tagger(k, key_expr)

        def ok(payload: bytes, attachment: bytes | None) -> bool:
            return attachment is not None and hmac.compare_digest(attachment, expected(payload))

        ok.prefix = expected.prefix  # type: ignore[attr-defined] - `copy_of`: a hot path checks inline
        return ok
