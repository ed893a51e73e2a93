"""Deterministic lockstep time (design.md section 3).

The links are here; what runs a loop over them, the drivers, is runtime/drivers.py.

Conservative synchronisation with lookahead:

* Every link has a **schedule** (period and phase, in ticks): its sender emits
  exactly one frame at every scheduled tick, empty or not, so the receiver
  always knows which frame it is waiting for.
* Every link has a **lag** >= 0: a frame sent at tick s is never delivered
  before tick s + lag. To act at tick k, a receiver needs every frame sent at
  or before k - lag, and no other. With lag 1 on every link but the engine's
  `sense` (lag 0), all processes can work on neighbouring ticks in parallel.
* Link emulation happens on the receiving side, frame by frame in send order,
  with the link's own seeded RNG: a dropped frame still arrives and is then
  discarded (nobody waits for it); a delayed frame is held until its delivery
  tick ``s + max(lag, ceil(delay / dt))``: delays are rounded **up** to the
  receiver's next tick.

A run is thus a pure function of (configuration, seed), whatever the OS
scheduler does. Frames arrive in order per sender (zenoh, RELIABLE); a frame
whose tick is not the next scheduled one, or that does not decode as the key's
message type, is rejected with a logged reason and counted.

Bounded waits: a receiver that has waited `wait_timeout` seconds of wall time
for a frame, or whose sender's liveliness token vanished, treats the sender as
dead, records it, and stops waiting for that link. (Wall time is used only to
detect failures, never for simulation behaviour.)

In real-time mode nothing blocks but a process's clock link; other links are
polled, and a frame is delivered ceil(delay / dt) ticks after the tick at which
it was polled.
"""

from __future__ import annotations

import hashlib
import heapq
import logging
import math
import threading
from collections import Counter
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import msgspec

from arena.runtime.clock import MONOTONIC, Clock
from arena.runtime.links import LinkEmulator
from arena.runtime.transport import WAKE, Channel, Transport
from arena.schemas.keys import MAX_BATCH, MAX_FRAME_BYTES
from arena.schemas.messages import Base
from arena.schemas.validate import SUSPECT_CLASSES, nonfinite, safe_default, starts_nonfinite, suspect

M = TypeVar("M", bound=Base)
_heappush, _heappop = heapq.heappush, heapq.heappop


@dataclass(frozen=True)
class Schedule:
    """Ticks phase, phase + period, phase + 2 period, ..."""

    period: int = 1
    phase: int = 0

    def due(self, k: int) -> bool:
        return k >= self.phase and (k - self.phase) % self.period == 0

    def last_at_or_before(self, k: int) -> int:
        """The last scheduled tick <= k, or -1 if there is none."""
        if k < self.phase:
            return -1
        return k - (k - self.phase) % self.period

    def first_after(self, s: int) -> int:
        if s < self.phase:
            return self.phase
        return s + self.period - (s - self.phase) % self.period

    def ticks(self, last: int) -> range:
        return range(self.phase, last + 1, self.period)


EVERY_TICK = Schedule(1, 0)


class Rejections:
    """Counts malformed, out-of-sequence and invalid inputs, logs the first ones of each kind.

    `conflicts` counts, per key, frames for a tick that already had a
    different accepted frame on that key: two senders on one key. `forged_by_key`
    counts, per key, frames dropped before the lockstep because their MAC did not
    check out (runtime/mac.py). Either is possible spoofing: the first one on a key
    is logged once as "possible spoofing on KEY", and the key is queued in
    `spoofed_new` for the process to announce (`Node.announce_spoofing`).
    """

    LOG_FIRST = 5

    def __init__(self, log: logging.Logger):
        self.log = log
        self.by_reason: Counter[str] = Counter()
        self.conflicts: Counter[str] = Counter()
        self.forged_by_key: Counter[str] = Counter()
        self.spoofed: set[str] = set()
        self.spoofed_new: list[str] = []
        # A forged frame is counted on the transport's thread, outside the lockstep's lock.
        self._lock = threading.Lock()

    def conflict(self, key: str, tick: int) -> None:
        with self._lock:
            self.conflicts[key] += 1
            self._spoofing(key)
            self.reject(key, "conflict", f"a second, different frame for tick {tick}")

    def forged(self, key: str, sender: str) -> None:
        """A frame on `key` without a valid MAC of `sender`: dropped before anything else looked at it."""
        with self._lock:
            self.forged_by_key[key] += 1
            self._spoofing(key)
            self.reject(key, "forged", f"not from {sender}")

    def _spoofing(self, key: str) -> None:
        if key not in self.spoofed:
            self.spoofed.add(key)
            self.spoofed_new.append(key)
            self.log.warning("possible spoofing on %s", key)

    @property
    def total(self) -> int:
        return sum(self.by_reason.values())

    def reject(self, key: str, reason: str, detail: str = "") -> None:
        self.by_reason[reason] += 1
        n = self.by_reason[reason]
        if n <= self.LOG_FIRST or n % 1000 == 0:
            self.log.warning("rejected input on %s: %s%s (%d so far)", key, reason, f": {detail}" if detail else "", n)


class Watchdog:
    """Bounds every blocking wait: wakes the waiting channel after `timeout` seconds.

    The main thread announces what it waits for (`arm`), the watchdog thread
    checks ten times a second and, past the deadline, delivers a local WAKE to
    that key's subscription. Cheap: no work on the hot path but two stores.
    """

    def __init__(self, transport: Transport, timeout: float, thread: bool = True, clock: Clock = MONOTONIC):
        self.transport = transport
        self.timeout = timeout
        self.clock = clock
        self._key: str | None = None
        self._since = 0.0
        self._stop = threading.Event()
        # No thread for a reactive node: its Reactor bounds the waits itself.
        self._thread = threading.Thread(target=self._run, name="watchdog", daemon=True) if thread else None
        if self._thread is not None:
            self._thread.start()

    def arm(self, key: str) -> None:
        self._since = self.clock.monotonic()
        self._key = key

    def disarm(self) -> None:
        self._key = None

    def expired(self) -> bool:
        return self._key is not None and self.clock.monotonic() - self._since >= self.timeout

    def _run(self) -> None:
        while not self.clock.wait(self._stop, 0.1):
            key = self._key
            if key is not None and self.clock.monotonic() - self._since >= self.timeout:
                self.transport.wake(key)

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)


def _drop(payload: bytes) -> None:
    return None


class Latest:
    """A put-through (`Outbound.put_through`) that keeps the last payload put, for a key
    whose sender also serves it (`Node.out(served=True)`)."""

    __slots__ = ("last", "_put")

    def __init__(self) -> None:
        self.last: bytes | None = None
        self._put: Callable[[bytes], None] = _drop

    def wrap(self, put: Callable[[bytes], None]) -> Latest:
        self._put = put
        return self

    def __call__(self, payload: bytes) -> None:
        self.last = payload
        put = self._put  # a local, then called: see `Outbound.send`
        put(payload)

    def get(self) -> bytes | None:
        return self.last


# The first byte of a msgpack array (fixarray, array 16, array 32): a batch of frames.
# A frame itself is always a map (schemas/messages.py `Base`), so the two never meet.
# A longer array than MAX_BATCH is rejected whole.
BATCH_HEADS = frozenset((*range(0x90, 0xA0), 0xDC, 0xDD))
decode_batch = msgspec.msgpack.Decoder(list[bytes]).decode


class Outbound(Generic[M]):
    """One outbound key: encodes, adds the frame to the process digest, publishes.

    `batch(n, last)`: put the frames of ticks k..k+n-1 (k a multiple of n) as one
    message, a msgpack array of the frames' bytes (schemas/README.md, "Batches"),
    and whatever is left at tick `last`. A transport detail: the frames, their
    digest and their order are the same whatever n is. A driver `flush`es a
    node's batches whenever the node is about to wait on a link that is not
    `paired` (`Node.batch_flusher`): a frame held back while its sender waits
    could be what, through other links, the sender waits for, a deadlock (L =
    16 with 16 frames a message did: the engine waited for a robot's `cmd` of
    tick 1, the robot for an `order` of tick 7). A `paired` link is the other
    half of the same aligned grid (the engine's `cmd` from a robot, a robot's
    `sense`): with n <= L, nothing held on one half is due on the other
    (config/__init__.py `frames_per_message`), and flushing there too cost
    ~5 % of a batched distributed match.

    `unbatched()`: one frame per message whatever `batch` asks (a cooperative
    match's node, where nothing goes on a wire: `Node.out`).
    """

    __slots__ = ("key", "rel", "_put", "_digest", "_encode", "sent", "_buf", "_size", "_last", "_heads", "_single")

    def __init__(self, key: str, rel: str, put: Callable[[bytes], None], digest: hashlib.blake2b):
        self.key = key
        self.rel = rel.encode()
        self._put = put
        self._digest = digest
        self._encode = msgspec.msgpack.Encoder().encode
        self.sent = 0
        self._buf: list[bytes] | None = None  # None: one frame per message
        self._size = 1
        self._last = 0
        self._heads: dict[int, bytes] = {}  # payload length -> rel + that length, as the digest takes them
        self._single = False  # `unbatched`

    def unbatched(self) -> None:
        """One frame per message from now on, whatever `batch` asks: the same frames, digest and order."""
        self._single = True
        self.batch(1, self._last)

    def batch(self, size: int, last: int) -> None:
        """Send `size` frames per message (ticks aligned to multiples of `size`); 1: one per message."""
        if self._single:
            size = 1
        self._buf = [] if size > 1 else None
        self._size = size
        self._last = last

    @property
    def batching(self) -> bool:
        return self._buf is not None

    def flush(self) -> None:
        """Put what the batch holds now (before a wait, or at the end of a loop that stopped early)."""
        buf = self._buf
        if buf:
            self._put(self._encode(buf))
            buf.clear()

    def mute(self) -> None:
        """Stop putting this key on the wire: its only receiver is dead (digest and count go on).

        A process runs its lockstep on zenoh's one network thread and puts with
        congestion control BLOCK; a put towards a stopped peer that comes back
        (SIGCONT) can then block that thread long enough for every lease on it
        to expire. Nobody waits for these frames any more, so none is sent.
        """
        self._put = _drop

    def put_through(self, wrap: Callable[[Callable[[bytes], None]], Callable[[bytes], None]]) -> None:
        """Put this key's frames through `wrap(put)` (runtime/pace.py `WireGate`); digest and count unchanged."""
        self._put = wrap(self._put)

    def send(self, msg: M) -> bytes:
        """Encode, digest and put `msg`; returns the payload (for a tap, runtime/tap.py)."""
        # An instance's callable read into a local, then called: `self._encode(msg)` compiles to a
        # LOAD_METHOD, which never specializes for an attribute (~300 instructions a call more).
        encode = self._encode
        payload = encode(msg)
        # The digest takes rel, the payload's length (4 bytes, little-endian), the payload: the
        # first two as one prebuilt header per length (the same bytes, one update less).
        n = len(payload)
        try:
            head = self._heads[n]  # a subscript, not `get`: no method call
        except KeyError:
            head = self._heads[n] = self.rel + n.to_bytes(4, "little")
        d = self._digest
        d.update(head)
        d.update(payload)
        self.sent += 1
        buf = self._buf
        if buf is None:
            put = self._put  # (a local: see `encode`)
            put(payload)
            return payload
        buf.append(payload)
        tick = msg.tick
        if (tick + 1) % self._size == 0 or tick >= self._last:
            self._put(self._encode(buf))
            buf.clear()
        return payload


# [frames] accepted frames per link kept (at least) to tell a conflicting frame for a past tick from a repeat.
RECENT = 256
NEVER = 1 << 62  # [ticks] past the last tick of any match

# A lockstep loop is a generator that yields (inbound, k) where it needs every
# frame of that link due at tick k; the driver resumes it once they are in.
Waits = Generator[tuple["Inbound[Any]", int], None, None]


class Inbound(Generic[M]):
    """One inbound link, in lockstep: schedule, lag, link emulation, validation."""

    # slots: an instance dict of 30 keys or more loses CPython 3.11's shared keys, and every method call
    # on the instance then costs ~250 instructions more
    __slots__ = (
        "key msg_type _decode channel schedule _period lag link_class sender emulator _dt_ms _rej _watchdog "
        "_is_dead _on_dead _check strict paired last_seen dead _next _hold ready_below woken _pending latest "
        "_mask _recent _prev _stood_in _dropped_ticks waited _last_at _on_time link __dict__"
    ).split()

    def __init__(
        self,
        *,
        key: str,
        msg_type: type[M],
        channel: Channel | None,  # None: the driver connects it (runtime/drivers.py `Driver.connect`)
        schedule: Schedule,
        lag: int,
        link_class: str,
        sender: str,
        emulator: LinkEmulator,
        dt: float,
        rejections: Rejections,
        watchdog: Watchdog | None,  # bounds `sync` and `recv_clock`; None where nothing blocks in them
        is_dead: Callable[[str], bool],
        on_dead: Callable[[str, str], None],
        check: Callable[[M], str | None] | None = None,
    ):
        self.key = key
        self.msg_type = msg_type
        self._decode = msgspec.msgpack.Decoder(msg_type).decode
        self.channel = channel
        self.schedule = schedule
        self._period = schedule.period
        self.lag = lag
        self.link_class = link_class
        self.sender = sender
        self.emulator = emulator
        self._on_time = emulator.on_time  # `emulator.on_time`, kept here (one attribute read less a frame)
        self._dt_ms = dt * 1000.0
        self._rej = rejections
        self._watchdog = watchdog
        self._is_dead = is_dead
        self._on_dead = on_dead
        self._check = check
        self.strict = True  # lockstep; False in real-time mode
        self.paired = False  # its sender batches on our batches' grid: no flush before waiting on it (`Outbound`)
        self.last_seen = -1  # tick of the last accepted frame
        self.dead = False
        # `ready(k)` is `k < ready_below`: the next frame due, `_next` (the tick it is sent at), is
        # needed from tick `_next + lag` on. Kept by `_accept_one`, and past every k once the sender
        # is dead (`_hold` then adds NEVER), so that a wait costs a comparison, not a call.
        self._next = schedule.first_after(-1)
        self._hold = lag
        self.ready_below = self._next + lag
        self.woken = False  # reactive mode: a WAKE came (a peer's token vanished)
        self._pending: list[tuple[int, int, M]] = []  # a heap of (deliver tick, send tick, message)
        # The largest deliver tick ever pushed: a frame due at or after it (with a later send tick) is
        # the heap's largest, and an append leaves the list as a push would.
        self._last_at = -1
        self.latest: M | None = None  # the last delivered message
        # The payloads of (at least) the last RECENT accepted frames (conflicts), tick t's in slot t & _mask:
        # a power of two of slots, at least RECENT periods.
        self._mask = (1 << (RECENT * schedule.period - 1).bit_length()) - 1
        self._recent: list[bytes | None] = [None] * (self._mask + 1)
        self._prev: M | None = None  # the last accepted message (an invalid frame's stand-in)
        self._stood_in = -1  # the last tick whose accepted frame was invalid, stood in for by a safe default
        self._dropped_ticks: list[int] = []  # send ticks of the frames the link emulation dropped (`counted`)
        self.waited = -1  # the last k its lockstep loop yielded it with (set by the drivers' `advance`)
        # Its cooperative link (runtime/coop.py `CoopLink`), which takes every frame in as it is put: a frame
        # taken in may wake its parked task, and a wait has nothing to settle (runtime/drivers.py `advance`).
        self.link: Any = None

    # ------------------------------------------------------------------ intake
    def _accept(self, raw: bytes, now_tick: int | None) -> bool:
        """Decode, check sequence, emulate the link. Returns True if it was a frame."""
        if raw == WAKE:
            return False
        return self._accept_frame(raw, now_tick)

    def _accept_frame(self, raw: bytes, now_tick: int | None) -> bool:
        """`_accept` for what is known not to be a WAKE: one frame, or a batch of them (`Outbound.batch`)."""
        if len(raw) > MAX_FRAME_BYTES:  # not even decoded: 60,000 robots in a sense took the decoder ~40 ms
            self._rej.reject(self.key, "too-large", f"{len(raw)} bytes, at most {MAX_FRAME_BYTES}")
            return False
        if raw and raw[0] in BATCH_HEADS:
            try:
                frames = decode_batch(raw)
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self._rej.reject(self.key, "malformed", f"batch: {str(exc)[:120]}")
                return False
            if not frames or len(frames) > MAX_BATCH:
                self._rej.reject(self.key, "malformed", f"a batch of {len(frames)} frames (1 to {MAX_BATCH})")
                return False
            # A frame's bytes lie whole in its batch's: a batch without the byte pair of a
            # non-finite float (schemas/validate.py `suspect`) has no frame with it.
            clean = not suspect(raw)
            got = False
            for frame in frames:
                got = self._accept_one(frame, now_tick, clean) or got
            return got
        return self._accept_one(raw, now_tick, False)

    def _accept_one(self, raw: bytes, now_tick: int | None = None, clean: bool | None = None) -> bool:
        """One frame's bytes: decode, check the sequence, emulate the link, wake the task parked on
        its cooperative link (`link`) once it is ready. `clean`: True, known to hold no non-finite
        float (its batch was scanned); False, scanned for every float header (`validate.suspect`);
        None (`_accept_one(raw)` alone, what a cooperative link's own publishers put, runtime/coop.py
        `CoopLink.own`): an `Outbound`'s frame, where msgspec writes every float as a float64 (0xcb),
        so only a 0xcb header before the first byte of a non-finite value can make it suspect. Every
        other caller says True or False."""
        scanned = clean
        if clean is None:  # one Python call a frame from an `Outbound` to here, not two
            if len(raw) > MAX_FRAME_BYTES:
                return self._accept_frame(raw, now_tick)
            # A pair only where its second byte is in the frame at all: `int in bytes` is one memchr,
            # no method call; `partition` (one argument, no parsing) looks for the pair only then.
            # (A batch, from an `Outbound` that batches, is known by its failing decode: below.)
            scanned = (
                (0x7F not in raw or not raw.partition(b"\xcb\x7f")[1])
                and (0xFF not in raw or not raw.partition(b"\xcb\xff")[1])
                or not starts_nonfinite(raw)
            )
        decode = self._decode  # a local, then called: see `Outbound.send`
        try:
            msg = decode(raw)
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            return self._undecoded(raw, now_tick, clean, exc)
        tick = msg.tick
        if self.strict:  # lockstep: exactly the next scheduled tick
            if tick != self._next:
                return self._refuse(raw, msg, f"tick {tick}, expected {self._next}")
            # `first_after(tick)` of a tick on the schedule
            self._next = nxt = tick + self._period
        elif tick <= self.last_seen:
            return self._refuse(raw, msg, f"tick {tick} after {self.last_seen}")
        else:
            self._next = nxt = self.schedule.first_after(tick)
            # An ideal link's frame counted here (`decide` counts the others): only real time reads the
            # count (`counted`), so a lockstep frame pays nothing for it.
            self.emulator.frames += self._on_time
        self.ready_below = nxt + self._hold
        # A ring by tick: one store a frame (a dict of ticks and a deque of their order took ~1 % of
        # an in-process match).
        self._recent[tick & self._mask] = raw
        # In sequence: the link advances whatever the content. A frame that fails
        # validation is counted and replaced by the key's safe default
        # (schemas/validate.py), so nobody waits for a frame that will never come.
        # `suspect(raw)` inlined (one call less a frame; b"\x01\x02" is its SUSPECT_PAIR, a constant here)
        # A payload without either first byte of a non-finite value is not translated (one memchr each).
        problem = (
            None
            if scanned or 0x7F not in raw and 0xFF not in raw or raw.translate(SUSPECT_CLASSES).find(b"\x01\x02") < 0
            else nonfinite(raw, msg)
        )
        if problem is None and (check := self._check) is not None:
            problem = check(msg)
        if problem:
            msg = self._stand_in(msg, problem)
        else:
            self._prev = msg
        self.last_seen = tick
        if self._on_time:  # `decide` inlined for an ideal link: held for `lag` (counted above in real time)
            if msg is not None:
                at = (tick if now_tick is None else now_tick) + self.lag
                if at >= self._last_at:  # every frame of an ideal link: no push's compare (~300 instructions)
                    self._last_at = at
                    self._pending.append((at, tick, msg))
                else:
                    _heappush(self._pending, (at, tick, msg))
            # `_wake`, inlined (a cooperative link's every frame)
            if (link := self.link) is not None and (w := link.waiter) is not None and w.waiting[1] < self.ready_below:
                link.waiter = None
                wake = link._wake  # a local, then called: see `Outbound.send`
                wake(w)
            return True
        return self._emulate(msg, tick, now_tick)

    def _undecoded(self, raw: bytes, now_tick: int | None, clean: bool | None, exc: Exception) -> bool:
        """`_accept_one`'s frame that did not decode: an own `Outbound`'s batch (clean None; a frame is a
        map, never an array) goes to `_accept_frame`; anything else is malformed, counted."""
        if clean is None and raw and raw[0] in BATCH_HEADS:
            return self._accept_frame(raw, now_tick)
        self._rej.reject(self.key, "malformed", str(exc)[:120])
        return False

    def _emulate(self, msg: M | None, tick: int, now_tick: int | None) -> bool:
        """`_accept_one`'s end on a link that is not ideal: the link emulation decides the frame's fate."""
        em = self.emulator
        delay = em.decide(tick)
        self._on_time = em.on_time  # (a scenario's last link change made it ideal for good)
        if delay is None:
            self._dropped_ticks.append(tick)
        elif msg is not None:
            base = tick if now_tick is None else now_tick
            # A frame on time (every frame of an ideal link) is held for `lag`, which is what the formula gives for 0.
            hold = self.lag if delay == 0.0 else max(self.lag, math.ceil(delay / self._dt_ms - 1e-9))
            at = base + hold
            if at > self._last_at:
                self._last_at = at
            _heappush(self._pending, (at, tick, msg))
        self._wake()
        return True

    def _wake(self) -> None:
        """Wake the task parked on this link's cooperative channel if it is now ready (`CoopLink`)."""
        link = self.link
        if link is not None:
            w = link.waiter
            if w is not None and w.waiting[1] < self.ready_below:
                link.waiter = None
                link._wake(w)

    def _stand_in(self, msg: M, problem: str) -> M | None:
        """An invalid frame in sequence, counted: what stands in for it (schemas/validate.py `safe_default`)."""
        self._rej.reject(self.key, "invalid", problem)
        self._stood_in = msg.tick
        stand_in = safe_default(msg, self._prev)
        if stand_in is not None:
            self._prev = stand_in
        return stand_in  # type: ignore[return-value]

    def _refuse(self, raw: bytes, msg: M, why: str) -> bool:
        """A frame out of sequence: a conflict if a different frame was accepted for its tick, else counted."""
        tick = msg.tick
        if tick <= self.last_seen:
            # The frame in tick's slot is tick's if it says so (it decoded when it was accepted);
            # else tick is older than the last RECENT frames, or none was accepted for it.
            kept = self._recent[tick & self._mask]
            if kept is not None and kept != raw and self._decode(kept).tick == tick:
                self._conflict(raw, msg)
                return False
        self._rej.reject(self.key, "out-of-sequence", why)
        return False

    def counted(self) -> tuple[int, int, list[float]]:
        """(frames, dropped, delays [ms] of the delivered ones) of this link, for the match's summary.

        In lockstep only the frames its loop waited for count: those sent at or
        before `waited` - lag, which every run takes in. The frames after them
        race the end of the match (a sender a tick ahead of a receiver that has
        stopped waiting, whose summary may be taken before they land), so
        counting them made the figure differ between runs of the same seed
        (72004, 72006, 72012 sensor frames in three 2 x 60 s matches). In real
        time every frame taken in counts.
        """
        e = self.emulator
        if not self.strict:
            return e.frames, e.dropped, e.delays_ms
        through = min(self.schedule.last_at_or_before(self.waited - self.lag), self.last_seen)
        frames = len(self.schedule.ticks(through))
        dropped = sum(1 for t in self._dropped_ticks if t <= through)
        return frames, dropped, e.delays_ms[: frames - dropped]

    def _conflict(self, raw: bytes, msg: M) -> None:
        """A second, different frame for a tick already accepted: two senders on one key.

        Counted, whatever its tick (a genuine frame that comes after a forged one is
        a conflict, not out-of-sequence). If it is for the tick just accepted, the
        accepted one was invalid (a safe default stands in for it), and this one is
        valid and not yet delivered, this one takes its place.
        """
        self._rej.conflict(self.key, msg.tick)  # type: ignore[attr-defined]
        if (
            msg.tick != self.last_seen
            or self._stood_in != msg.tick
            or nonfinite(raw, msg)
            or (self._check is not None and self._check(msg))
        ):
            return
        for i, (at, tick, _) in enumerate(self._pending):
            if tick == msg.tick:  # type: ignore[attr-defined]
                self._pending[i] = (at, tick, msg)  # same order keys: still a heap
                self._prev = msg
                self._stood_in = -1
                return

    # ------------------------------------------------- what drivers ask of a link
    def ready(self, k: int) -> bool:
        """Every frame sent at or before k - lag is in (or the sender is dead).

        That is, no frame is due after `last_seen` and at or before k - lag: the
        next one, sent at `_next`, is needed from `_next + lag` on (`ready_below`)."""
        return k < self.ready_below

    def drain(self) -> None:
        """Lockstep, never blocking: take in whatever has arrived on the channel (the cooperative driver)."""
        ch = self.channel
        while (raw := ch.try_recv()) is not None:  # type: ignore[union-attr]
            if raw != WAKE:  # `_accept`, one call less a message
                self._accept_frame(raw, None)

    def sender_gone(self) -> bool:
        """Its sender's liveliness token has vanished."""
        return self._is_dead(self.sender)

    def feed(self, raw: bytes) -> None:
        """Reactive lockstep: one frame from the transport's callback (see `Reactor`)."""
        if raw == WAKE:
            self.woken = True  # looked at by the Reactor only when it waits on this link
            return
        self._accept_frame(raw, None)

    def sync(self, k: int) -> None:
        """Block until every frame sent at or before k - lag is in (lockstep)."""
        target = self.schedule.last_at_or_before(k - self.lag)
        if self.last_seen >= target or self.dead:
            return
        ch = self.channel
        wd = self._watchdog
        while self.last_seen < target:
            raw = ch.try_recv()
            expired = False
            if raw is None:
                wd.arm(self.key)
                raw = ch.recv()
                expired = wd.expired()
                wd.disarm()
            if raw == WAKE:
                # A wake-up means a dead peer or a timeout; a stale one is ignored.
                if self.sender_gone():
                    self.give_up("its liveliness token vanished")
                    return
                if expired:
                    self.give_up(f"silent for {wd.timeout:g} s waiting for tick {target}")
                    return
                continue
            self._accept(raw, None)

    def poll(self, now_tick: int) -> None:
        """Real-time mode: take whatever has arrived, never block."""
        while True:
            raw = self.channel.try_recv()
            if raw is None:
                return
            self._accept(raw, now_tick)

    def recv_clock(self) -> int | None:
        """Real-time mode, clock link: block for the next frame; returns its tick."""
        ch = self.channel
        wd = self._watchdog
        while True:
            wd.arm(self.key)
            raw = ch.recv()
            expired = wd.expired()
            wd.disarm()
            if raw == WAKE:
                if expired or self.sender_gone():
                    self.give_up("silent in real-time mode")
                    return None
                continue
            before = self.last_seen
            if self._accept(raw, None) and self.last_seen > before:
                return self.last_seen

    def give_up(self, why: str) -> None:
        """Stop waiting for this link (its sender is dead); `why` is recorded with the sender."""
        self.dead = True
        self._hold = self.ready_below = NEVER
        self._on_dead(self.sender, f"{self.key}: {why}")

    # ---------------------------------------------------------------- delivery
    def take(self, k: int) -> list[M]:
        """Frames delivered by tick k, in delivery order; also updates `latest`.

        Jitter can reorder frames, as on a real network; `latest` is the newest
        by send tick, so a late old frame never replaces fresher news.
        """
        pending = self._pending
        if not pending or pending[0][0] > k:
            return []  # nothing due: the usual case for most links at most ticks
        msg = _heappop(pending)[2]
        latest = self.latest
        if latest is None or msg.tick > latest.tick:
            latest = msg
        out = [msg]  # one frame due: the usual case when there is any
        while pending and pending[0][0] <= k:
            msg = _heappop(pending)[2]
            out.append(msg)
            if msg.tick > latest.tick:
                latest = msg
        self.latest = latest
        return out

    def latest_by(self, k: int) -> M | None:
        """`take(k)`, for a receiver that reads only `latest`: no list of the frames taken."""
        pending = self._pending
        if not pending or pending[0][0] > k:
            return self.latest
        latest = self.latest
        while pending and pending[0][0] <= k:
            msg = _heappop(pending)[2]
            if latest is None or msg.tick > latest.tick:
                latest = msg
        self.latest = latest
        return latest
