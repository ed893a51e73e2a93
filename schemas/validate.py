"""What a receiver does with a frame that decodes but cannot be used.

Two things, for every message type:

* `nonfinite(raw, msg)`: a NaN or an infinity anywhere in the message (a
  strategy that divided by zero, a forged frame) names the first such field.
  The raw payload is scanned first for the msgpack float headers of a
  non-finite value (0xcb/0xca then the first byte of an all-ones exponent);
  only a payload where such a pair does start one (`starts_nonfinite`) is
  walked field by field, so a clean frame costs two byte searches (no 0x7f or
  0xff at all), or one translation and one byte scan.
* `safe_default(msg, previous)`: what an in-sequence frame that failed
  validation is replaced by, so its link still advances and nobody waits for a
  frame that will never come (docs/architecture.md, "Faults"): a `cmd` stops
  the wheels and never kicks; an `engine/events` or `referee` frame carries no
  new events or commands (a repeated GOAL would count twice); any other key
  repeats the previous good message of its link, or delivers nothing if there
  was none yet.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import msgspec

from arena.schemas.messages import Base, Cmd, EngineEvents, Referee

# msgpack float 64 (0xcb) and float 32 (0xca), big-endian: a non-finite value has
# its exponent bits all set, so its first byte is 0x7f or 0xff. Translated through
# SUSPECT_CLASSES (a header to 1, such a first byte to 2, any other byte to 0), a payload
# holds SUSPECT_PAIR where it holds any of the four pairs: one scan instead of four,
# which were ~6 % of a match's CPU in one process.
SUSPECT_CLASSES = bytes(1 if b in (0xCA, 0xCB) else 2 if b in (0x7F, 0xFF) else 0 for b in range(256))
SUSPECT_PAIR = b"\x01\x02"


def first_problem(value: object, leaf: Callable[[object, str], str | None], path: str = "") -> str | None:
    """What `leaf(x, path)` says of the first of `value`'s scalars it has something to say of, walking
    struct fields, lists, tuples and dicts (a field's path as `robots[2].x`), or None."""
    if isinstance(value, Base):
        for name in value.__struct_fields__:
            problem = first_problem(getattr(value, name), leaf, f"{path}.{name}" if path else name)
            if problem:
                return problem
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            problem = first_problem(item, leaf, f"{path}[{i}]")
            if problem:
                return problem
    elif isinstance(value, dict):
        for k, item in value.items():
            problem = first_problem(item, leaf, f"{path}[{k!r}]")
            if problem:
                return problem
    else:
        return leaf(value, path)
    return None


def _not_finite(value: object, path: str) -> str | None:
    return f"{path or 'value'} is not finite" if type(value) is float and not math.isfinite(value) else None


def nonfinite(raw: bytes, msg: Base) -> str | None:
    """The first non-finite float in `msg` (decoded from `raw`), or None."""
    return first_problem(msg, _not_finite) if suspect(raw) and starts_nonfinite(raw) else None


# (a float header and the first byte of a non-finite value, the least second byte of one): its
# exponent's bits all set, 11 of a float64's (0xf0 and over), 8 of a float32's (0x80 and over).
_NONFINITE_STARTS = ((b"\xcb\x7f", 0xF0), (b"\xcb\xff", 0xF0), (b"\xca\x7f", 0x80), (b"\xca\xff", 0x80))


def starts_nonfinite(raw: bytes) -> bool:
    """Whether a pair `suspect` finds starts a non-finite value: found in a float's other bytes
    (about 1 frame in 600 of a match), it is not walked field by field for nothing."""
    last = len(raw) - 3
    for pair, least in _NONFINITE_STARTS:
        i = raw.find(pair)
        while i >= 0:
            if i > last or raw[i + 2] >= least:
                return True
            i = raw.find(pair, i + 1)
    return False


def suspect(raw: bytes) -> bool:
    """Whether `raw` holds a msgpack float header followed by the first byte of a non-finite value."""
    # `find`, not `in`: bytes' `in` first tries its operand as an integer, and builds and drops a
    # TypeError's message for every other operand (~1,800 instructions a call, more than the scan).
    # An integer's `in` is one memchr: a payload without either first byte is not translated at all
    # (about half the frames of a match; ~4.1 k -> 2.5 k instructions a frame).
    return (0x7F in raw or 0xFF in raw) and raw.translate(SUSPECT_CLASSES).find(SUSPECT_PAIR) >= 0


def safe_default(msg: Base, previous: Base | None) -> Base | None:
    """The replacement for `msg`, an in-sequence frame that failed validation (None: deliver nothing)."""
    tick = msg.tick  # type: ignore[attr-defined]
    if isinstance(msg, Cmd):
        return Cmd(tick=tick)
    if isinstance(msg, EngineEvents):
        return EngineEvents(tick=tick)
    if previous is None:
        return None
    if isinstance(previous, Referee):
        return msgspec.structs.replace(previous, tick=tick, commands=[])
    return msgspec.structs.replace(previous, tick=tick)
