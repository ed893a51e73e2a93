"""The transport behind a small interface: zenoh for real, memory for unit tests.

Processes see only `Transport`: publishers, pull-style subscriptions (the
main thread blocks in `recv`, the fastest receive style measured on 2 cores,
see notes-zenoh-mcap.md), a local wake-up, liveliness, queryables (the match
configuration, the field, the last frame of a `SERVED` key) and queries, the
viewer's without waiting (`ask`). `MemoryTransport` implements the same interface in
one Python process, so process logic can be driven with scripted inputs and no
zenoh at all; it is never what a feature claims to run on.
"""

from __future__ import annotations

import _thread
import ctypes
import functools
import hmac
import queue
import threading
from collections import defaultdict
from collections.abc import Callable
from typing import Protocol

import zenoh

from arena.runtime import mac

# Threads that hold a Python thread state of their own for good (`keep_thread_state`).
_KEPT: set[int] = set()


def keep_thread_state() -> None:
    """Give the zenoh thread running this callback a Python thread state for good.

    zenoh-python runs a callback on a thread Python did not start, through
    `PyGILState_Ensure`/`PyGILState_Release`. A thread without a state of its
    own gets a fresh one for every callback and loses it on return, and in
    CPython 3.11 that costs an mmap and a munmap of the frame stack, page
    faults on touching it, and a TLB shoot-down across the cores: `strace`
    showed one mmap/munmap/gettid triple per message in every process. One
    extra `PyGILState_Ensure`, never released, keeps the state alive; zenoh's
    own Ensure/Release pairs then just take and drop the GIL (the measurement:
    docs/performance.md, "Measurements behind design choices").
    """
    ident = _thread.get_ident()
    if ident not in _KEPT:
        _KEPT.add(ident)
        ctypes.pythonapi.PyGILState_Ensure()  # PyDLL: called with the GIL held, as it must be


# 0xc1 is the one byte msgpack never uses, so a wake-up can never be a message.
WAKE = b"\xc1arena-wake"


class Channel(Protocol):
    def recv(self) -> bytes: ...
    def try_recv(self) -> bytes | None: ...


# verify(payload, attachment) -> bool, and what to call for a frame that fails it (runtime/mac.py)
Verify = Callable[[bytes, bytes | None], bool]
Sign = Callable[[bytes], bytes]


class Transport(Protocol):
    def publisher(self, key: str, when_matched: bool = False, sign: Sign | None = None) -> Callable[[bytes], None]:
        """A put function for `key`. With `when_matched`, puts are skipped while no
        remote subscriber matches (for keys nobody in the lockstep waits on).
        With `sign`, every put carries `sign(payload)` as its attachment (a MAC)."""

    def subscribe(
        self, key: str, latest: int = 0, verify: Verify | None = None, on_forged: Callable[[], None] | None = None
    ) -> Channel:
        """`latest` > 0: keep only the newest `latest` frames (a viewer), never block zenoh.
        With `verify`, frames that fail it are dropped and `on_forged()` is called instead."""

    def subscribe_callback(
        self,
        key: str,
        callback: Callable[[bytes], None],
        verify: Verify | None = None,
        on_forged: Callable[[], None] | None = None,
    ) -> None:
        """Run `callback(payload)` on the transport's own thread for every frame of `key`."""

    def wake(self, key: str) -> None:
        """Deliver WAKE to this process's own subscribers of `key` only."""

    def has_subscribers(self, key: str) -> bool:
        """Whether a remote subscriber matches this process's publisher of `key` (True if unknown)."""

    def declare_alive(self, key: str) -> None: ...
    def watch_alive(self, key_expr: str, on_change: Callable[[str, bool], None]) -> None: ...
    def serve(self, key: str, payload: bytes | Callable[[], bytes | None], sign: Sign | None = None) -> None:
        """Answer queries on `key` with `payload`, or with what `payload()` returns at the time (None: no answer).
        With `sign`, every answer carries `sign(answer)` as its attachment (a MAC)."""

    def query(
        self, key: str, timeout: float, verify: Verify | None = None, on_forged: Callable[[], None] | None = None
    ) -> bytes | None:
        """The first answer to a query on `key` (None: none within `timeout`). With `verify`, every
        answer is looked at and the ones that fail it are dropped, `on_forged()` called for each."""

    def ask(
        self,
        key: str,
        on_reply: Callable[[bytes], None],
        timeout: float,
        verify: Verify | None = None,
        on_forged: Callable[[], None] | None = None,
    ) -> None:
        """Query `key` without waiting: `on_reply(payload)` runs on the transport's thread for each answer
        (with `verify`, each that passes it)."""

    def close(self) -> None: ...


# ---------------------------------------------------------------------- zenoh
def _attachment(sample: zenoh.Sample) -> bytes | None:
    a = sample.attachment
    return None if a is None else a.to_bytes()


class _ZenohChannel:
    __slots__ = ("_sub",)

    def __init__(self, sub: zenoh.Subscriber):
        self._sub = sub

    def recv(self) -> bytes:
        return self._sub.recv().payload.to_bytes()

    def try_recv(self) -> bytes | None:
        s = self._sub.try_recv()
        return None if s is None else s.payload.to_bytes()


class _VerifiedChannel:
    """A channel that hands on only frames whose MAC checks out (and local wake-ups)."""

    __slots__ = ("_sub", "_verify", "_on_forged")

    def __init__(self, sub: zenoh.Subscriber, verify: Verify, on_forged: Callable[[], None] | None):
        self._sub = sub
        self._verify = verify
        self._on_forged = on_forged

    def _check(self, s: zenoh.Sample) -> bytes | None:
        payload = s.payload.to_bytes()
        if payload == WAKE or self._verify(payload, _attachment(s)):
            return payload
        if self._on_forged is not None:
            self._on_forged()
        return None

    def recv(self) -> bytes:
        while True:
            payload = self._check(self._sub.recv())
            if payload is not None:
                return payload

    def try_recv(self) -> bytes | None:
        while (s := self._sub.try_recv()) is not None:
            payload = self._check(s)
            if payload is not None:
                return payload
        return None


class ZenohTransport:
    """Lockstep traffic is RELIABLE with congestion control BLOCK: nothing is dropped by zenoh.

    Not `express`: it costs more CPU per put for no lockstep latency gain
    (docs/performance.md, "Measurements behind design choices").
    """

    FIFO = 1 << 14  # frames buffered per subscription

    def __init__(self, session: zenoh.Session, keyring: object = None):
        self.session = session
        self.keyring = keyring  # runtime/mac.Keyring of this process, if it has credentials
        self._keep: list[object] = []  # declared entities live as long as the transport
        self._wakers: dict[str, zenoh.Publisher] = {}
        self._wake_lock = threading.Lock()
        self._pubs: dict[str, zenoh.Publisher] = {}

    def has_subscribers(self, key: str) -> bool:
        pub = self._pubs.get(key)
        return pub is None or pub.matching_status.matching

    def publisher(self, key: str, when_matched: bool = False, sign: Sign | None = None) -> Callable[[bytes], None]:
        # A key nobody in the lockstep waits for (`world`, for viewers) never blocks its
        # sender: a viewer that falls behind loses frames instead of slowing the match.
        pub = self.session.declare_publisher(
            key,
            encoding=zenoh.Encoding("application/msgpack"),
            congestion_control=zenoh.CongestionControl.DROP if when_matched else zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.RELIABLE,
            express=False,
        )
        self._keep.append(pub)
        self._pubs[key] = pub
        raw_put = pub.put
        if sign is not None:
            raw_put = _signed(pub.put, sign)
        if not when_matched:
            return raw_put
        matched = [True]

        def on_change(status: zenoh.MatchingStatus) -> None:
            matched[0] = status.matching

        self._keep.append(pub.declare_matching_listener(on_change))
        # The status's `matching` (the status object itself is always true: every `world` frame was
        # signed and put with nobody subscribed), read once the listener is there. Read again after
        # it is set false: a subscriber that came between the first read and that store was heard
        # by the listener before the store, and is seen by the second read. A stale true costs puts only.
        if not pub.matching_status.matching:
            matched[0] = False
            if pub.matching_status.matching:
                matched[0] = True

        def put(payload: bytes) -> None:
            if matched[0]:
                raw_put(payload)

        return put

    def subscribe(
        self, key: str, latest: int = 0, verify: Verify | None = None, on_forged: Callable[[], None] | None = None
    ) -> Channel:
        """`latest` > 0: keep only the newest `latest` frames (a viewer), never block zenoh."""
        handler = zenoh.handlers.RingChannel(latest) if latest > 0 else zenoh.handlers.FifoChannel(self.FIFO)
        sub = self.session.declare_subscriber(key, handler)
        self._keep.append(sub)
        # The wake-up for this subscription goes through a publisher of its own,
        # declared now on the main thread: `wake` runs on other threads (watchdog,
        # liveliness callback), and a session call there can collide with the
        # main thread's ("Already mutably borrowed").
        self._wakers[key] = self.session.declare_publisher(key, allowed_destination=zenoh.Locality.SESSION_LOCAL)
        return _ZenohChannel(sub) if verify is None else _VerifiedChannel(sub, verify, on_forged)

    def subscribe_callback(
        self,
        key: str,
        callback: Callable[[bytes], None],
        verify: Verify | None = None,
        on_forged: Callable[[], None] | None = None,
    ) -> None:
        on_sample = _on_sample(callback, verify, on_forged)
        # indirect=False: run on zenoh's receive thread itself. The default hands
        # every sample to a Python thread of its own, one more wake-up per frame.
        handler = zenoh.handlers.Callback(on_sample, indirect=False)
        self._keep.append(self.session.declare_subscriber(key, handler))
        self._wakers[key] = self.session.declare_publisher(key, allowed_destination=zenoh.Locality.SESSION_LOCAL)

    def wake(self, key: str) -> None:
        # Looked up under the lock: `close` undeclares the wakers under it, and a
        # liveliness callback racing the close must find none, not a dead one.
        with self._wake_lock:
            waker = self._wakers.get(key)
            if waker is not None:
                waker.put(WAKE)

    def declare_alive(self, key: str) -> None:
        self._keep.append(self.session.liveliness().declare_token(key))

    def declare_token(self, key: str) -> Callable[[], None]:
        """A liveliness token to take back later (a lockstep wait's, runtime/lockstep.py); returns its undeclare."""
        return self.session.liveliness().declare_token(key).undeclare

    def watch_alive(self, key_expr: str, on_change: Callable[[str, bool], None]) -> None:
        def cb(sample: zenoh.Sample) -> None:
            keep_thread_state()
            on_change(str(sample.key_expr), sample.kind == zenoh.SampleKind.PUT)

        self._keep.append(self.session.liveliness().declare_subscriber(key_expr, cb, history=True))

    def serve(self, key: str, payload: bytes | Callable[[], bytes | None], sign: Sign | None = None) -> None:
        def cb(query: zenoh.Query) -> None:
            keep_thread_state()
            answer = payload if isinstance(payload, bytes) else payload()
            if answer is not None:
                query.reply(key, answer, attachment=None if sign is None else sign(answer))

        self._keep.append(self.session.declare_queryable(key, cb))

    def query(
        self, key: str, timeout: float, verify: Verify | None = None, on_forged: Callable[[], None] | None = None
    ) -> bytes | None:
        found = None
        # Every answer is looked at, not only up to the first good one: each forged one is counted,
        # whichever came first. The query ends when every queryable has answered (or at `timeout`).
        # No consolidation: zenoh's default keeps one answer per key, and a stranger's could be it.
        for reply in self.session.get(key, timeout=timeout, consolidation=_every_answer(verify)):
            if reply.ok is None:
                continue
            payload = reply.ok.payload.to_bytes()
            if verify is None:
                return payload
            if not verify(payload, _attachment(reply.ok)):
                if on_forged is not None:
                    on_forged()
            elif found is None:
                found = payload
        return found

    def ask(
        self,
        key: str,
        on_reply: Callable[[bytes], None],
        timeout: float,
        verify: Verify | None = None,
        on_forged: Callable[[], None] | None = None,
    ) -> None:
        def cb(reply: zenoh.Reply) -> None:
            keep_thread_state()
            if reply.ok is None:
                return
            payload = reply.ok.payload.to_bytes()
            if verify is None or verify(payload, _attachment(reply.ok)):
                on_reply(payload)
            elif on_forged is not None:
                on_forged()

        self.session.get(key, cb, timeout=timeout, consolidation=_every_answer(verify))

    def close(self) -> None:
        with self._wake_lock:
            for waker in self._wakers.values():
                _undeclare(waker)
            self._wakers.clear()
        for entity in reversed(self._keep):
            _undeclare(entity)
        self._keep.clear()
        self._pubs.clear()


# Every frame of a lockstep match goes through one of these two, in the zenoh thread: each is
# one Python frame (the MAC of runtime/mac.py worked out inline, the thread state kept only the
# first time a thread comes), not the three to five calls of a signer, a verifier and their helpers.
def _signed(pub_put: Callable[..., None], sign: Sign) -> Callable[[bytes], None]:
    """`pub_put(payload, attachment=sign(payload))` as one function."""
    copy = mac.copy_of(sign)
    if copy is None:
        return lambda payload: pub_put(payload, attachment=sign(payload))

    def signed_put(payload: bytes) -> None:
        h = copy()
        h.update(payload)
        pub_put(payload, attachment=h.digest())

    return signed_put


def _on_sample(
    callback: Callable[[bytes], None], verify: Verify | None, on_forged: Callable[[], None] | None
) -> Callable[[zenoh.Sample], None]:
    """A zenoh callback: `callback(payload)` for a frame `verify` passes (or a WAKE), else `on_forged()`."""
    kept, ident = _KEPT, _thread.get_ident
    if verify is None:

        def on_sample(sample: zenoh.Sample) -> None:
            if ident() not in kept:
                keep_thread_state()
            callback(sample.payload.to_bytes())

        return on_sample
    copy, equal = mac.copy_of(verify), hmac.compare_digest

    def on_verified(sample: zenoh.Sample) -> None:
        if ident() not in kept:
            keep_thread_state()
        payload = sample.payload.to_bytes()
        if copy is None:
            good = verify(payload, _attachment(sample))
        elif (a := sample.attachment) is None:
            good = False
        else:
            h = copy()
            h.update(payload)
            good = equal(a.to_bytes(), h.digest())
        if good or payload == WAKE:
            callback(payload)
        elif on_forged is not None:
            on_forged()

    return on_verified


def _every_answer(verify: Verify | None) -> zenoh.ConsolidationMode | None:
    """A verified query takes every answer (`query`); an unverified one, zenoh's default."""
    return None if verify is None else zenoh.ConsolidationMode.NONE


def _undeclare(entity: object) -> None:
    """Undeclare `entity` unless zenoh's thread is using it right now.

    A SIGTERM lands on the main thread while a reactive node's lockstep runs in
    a zenoh callback; if that callback is inside `put` on a publisher, pyo3
    refuses to undeclare it (`RuntimeError: Already borrowed`) and the process
    died with a traceback instead of exiting. Such an entity is left to the
    session's own close, which undeclares everything it has.
    """
    undeclare = getattr(entity, "undeclare", None)
    if undeclare is None:
        return
    try:
        undeclare()
    except RuntimeError:
        pass


# --------------------------------------------------------------------- memory
class _MemoryChannel:
    __slots__ = ("_q",)

    def __init__(self) -> None:
        self._q: queue.SimpleQueue[bytes] = queue.SimpleQueue()

    def recv(self) -> bytes:
        return self._q.get()

    def try_recv(self) -> bytes | None:
        try:
            return self._q.get_nowait()
        except queue.Empty:
            return None


class MemoryBus:
    """The shared 'network' of MemoryTransports: exact keys and trailing `/**`."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._subs: dict[str, list[tuple[object, _MemoryChannel]]] = defaultdict(list)
        self._alive: dict[str, object] = {}
        self._watchers: list[tuple[str, Callable[[str, bool], None]]] = []
        self._served: dict[str, bytes] = {}

    @staticmethod
    def matches(expr: str, key: str) -> bool:
        if expr.endswith("/**"):
            return key.startswith(expr[:-2]) or key == expr[:-3]
        return expr == key

    def deliver(self, key: str, payload: bytes, only: object | None = None) -> None:
        with self._lock:
            targets = [
                (owner, ch) for expr, subs in self._subs.items() if self.matches(expr, key) for owner, ch in subs
            ]
        for owner, ch in targets:
            if only is None or owner is only:
                ch._q.put(payload)

    def putter(self, key: str) -> Callable[[bytes], None]:
        """What a publisher of `key` puts with: `deliver(key, payload)`."""
        return functools.partial(self.deliver, key)

    def subscribe(self, owner: object, key: str) -> _MemoryChannel:
        ch = _MemoryChannel()
        with self._lock:
            self._subs[key].append((owner, ch))
        return ch

    def set_alive(self, key: str, owner: object, alive: bool) -> None:
        with self._lock:
            if alive:
                self._alive[key] = owner
            else:
                self._alive.pop(key, None)
            watchers = [cb for expr, cb in self._watchers if self.matches(expr, key)]
        for cb in watchers:
            cb(key, alive)

    def watch(self, expr: str, cb: Callable[[str, bool], None]) -> None:
        with self._lock:
            self._watchers.append((expr, cb))
            present = [k for k in self._alive if self.matches(expr, k)]
        for k in present:
            cb(k, True)


class MemoryTransport:
    def __init__(self, bus: MemoryBus):
        self.bus = bus
        self._tokens: list[str] = []

    def publisher(self, key: str, when_matched: bool = False, sign: Sign | None = None) -> Callable[[bytes], None]:
        # No attachments on the memory bus: it runs in one trusted process (unit tests).
        return self.bus.putter(key)

    def subscribe(self, key: str, latest: int = 0, verify=None, on_forged=None) -> Channel:
        return self.bus.subscribe(self, key)

    def subscribe_callback(self, key: str, callback: Callable[[bytes], None], verify=None, on_forged=None) -> None:
        # A callback would run in the sender's thread, inside the sender's own
        # tick: nodes on a memory bus pull from channels instead (runtime/drivers.py `Pull`).
        raise NotImplementedError("MemoryTransport delivers to channels only")

    def wake(self, key: str) -> None:
        self.bus.deliver(key, WAKE, only=self)

    def has_subscribers(self, key: str) -> bool:
        return True

    def declare_alive(self, key: str) -> None:
        self._tokens.append(key)
        self.bus.set_alive(key, self, True)

    def watch_alive(self, key_expr: str, on_change: Callable[[str, bool], None]) -> None:
        self.bus.watch(key_expr, on_change)

    def serve(self, key: str, payload: bytes | Callable[[], bytes], sign: Sign | None = None) -> None:
        self.bus._served[key] = payload  # no attachments on the memory bus (see `publisher`)

    def query(self, key: str, timeout: float, verify=None, on_forged=None) -> bytes | None:
        payload = self.bus._served.get(key)
        return payload if payload is None or isinstance(payload, bytes) else payload()

    def ask(self, key: str, on_reply: Callable[[bytes], None], timeout: float, verify=None, on_forged=None) -> None:
        payload = self.query(key, timeout)
        if payload is not None:
            on_reply(payload)

    def close(self) -> None:
        for key in self._tokens:
            self.bus.set_alive(key, self, False)
        self._tokens.clear()
