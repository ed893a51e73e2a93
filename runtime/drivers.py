"""Drivers: what runs a node's lockstep loop, and the one `advance` they share.

A lockstep loop is a generator that yields `(inbound, k)` wherever it needs
every frame of that link due at tick k (runtime/lockstep.py `Waits`). A driver
resumes it: `advance` runs it until it waits on a link that is not ready, and
the drivers differ only in how they wait for that link:

* `Pull` blocks in the link's `sync` on this thread (real time, the memory bus
  of the unit tests, anything without receive callbacks), bounded by a
  `Watchdog`;
* `Reactor` returns, and goes on in the transport's receive callback that
  brings the frame (lockstep over zenoh), bounded by its own look every 0.1 s;
* the cooperative driver (runtime/coop.py `Task`) parks the node, and its
  scheduler resumes it when a frame comes to that link: every node of a match
  in one thread.

Whoever drives, the loop takes the same frames in the same order, so a node's
digest is the same under every driver (tests/golden/digests.json).
"""

from __future__ import annotations

import functools
import resource
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

from arena.runtime.clock import MONOTONIC, Clock
from arena.runtime.lockstep import Inbound, Waits, Watchdog
from arena.runtime.transport import Transport
from arena.schemas.keys import WAITING, Keys

if TYPE_CHECKING:
    from arena.runtime.transport import Verify, ZenohTransport

Wait = tuple[Inbound[Any], int]  # what a loop yields: the link, and the tick whose frames it needs


class Driver(Protocol):
    """How a node's lockstep loop runs (`Node(driver=...)`).

    `cooperative`: every node of the match runs in this one thread, so nothing may
    block: no start barrier (every node is there by construction), and the lockstep
    loop is played even for a real-time configuration. `watchdog`: what bounds a blocking `Inbound.sync`
    or `recv_clock`, None where nothing blocks in them. `connect` makes `ib`'s frames
    reach it, through its channel or a receive callback. `drive` is a generator: a
    blocking driver runs the loop to its end inside it and yields nothing; a
    cooperative one yields the loop's waits to its scheduler. `before_wait` is
    called as the loop starts to wait on a link that is not `paired` (the node's
    held-back batches go out first, `Node.batch_flusher`).
    """

    cooperative: bool
    watchdog: Watchdog | None

    def connect(
        self, ib: Inbound[Any], transport: Transport, verify: Verify | None, on_forged: Callable[[], None]
    ) -> None: ...

    def drive(self, steps: Waits, before_wait: Callable[[], None] | None) -> Waits: ...

    def cpu_s(self) -> list[float]:
        """[user, system] CPU seconds this node took (the summary's `cpu_s`)."""
        ...

    def close(self) -> None: ...


def advance(
    steps: Waits,
    waiting: Wait | None,
    settle: Callable[[Inbound[Any], int], bool],
    before_wait: Callable[[], None] | None,
) -> Wait | None:
    """Resume `steps` until it waits on a link that is not ready: returns that wait, or None if the loop ended.

    `waiting` is the wait it stopped at last time (None at the start). `settle(ib, k)`
    is the driver's last look before it gives the wait back: it may take in what
    arrived or give up on a dead sender, and says whether the link is now ready.
    Each link yielded notes the tick it was last waited for (`Inbound.waited`, what
    its summary counts through).
    """
    while True:
        if waiting is not None:
            ib, k = waiting
            # `ib.ready(k)` of a link is `k < ib.ready_below`: a comparison, not a call. What duck-types
            # a link without keeping that bound (ready_below -1: the engine's pacer, a learner's gate) is asked.
            # A link on a cooperative `link` took every frame in as it was put: no `settle` call to ask.
            below = ib.ready_below
            if (
                k >= below
                and (below >= 0 or not ib.ready(k))
                and (below >= 0 and ib.link is not None or not settle(ib, k))
            ):
                if before_wait is not None and not ib.paired:
                    before_wait()
                return waiting
        waiting = next(steps, None)
        if waiting is None:
            return None
        waiting[0].waited = waiting[1]


def _not_yet(ib: Inbound[Any], k: int) -> bool:  # a blocking driver waits in `sync` instead
    return False


def own_cpu_s() -> list[float]:
    """[user, system] CPU seconds of this process."""
    return list(resource.getrusage(resource.RUSAGE_SELF)[:2])


def subscribe(ib: Inbound[Any], transport: Transport, verify: Verify | None, on_forged: Callable[[], None]) -> None:
    """`Driver.connect` for a driver that reads the link's channel."""
    ib.channel = transport.subscribe(ib.key, verify=verify, on_forged=on_forged)


class Pull:
    """Drive a lockstep loop from this thread, blocking in each link's `sync`, bounded by a `Watchdog`."""

    cooperative = False

    def __init__(self, transport: Transport, timeout: float, clock: Clock = MONOTONIC):
        self.watchdog: Watchdog | None = Watchdog(transport, timeout, clock=clock)

    connect = staticmethod(subscribe)
    cpu_s = staticmethod(own_cpu_s)

    def drive(self, steps: Waits, before_wait: Callable[[], None] | None = None) -> Waits:
        pull(steps, before_wait)
        yield from ()

    def close(self) -> None:
        if self.watchdog is not None:
            self.watchdog.stop()


def pull(steps: Waits, before_wait: Callable[[], None] | None = None) -> None:
    """Drive a lockstep loop from this thread, blocking in each link's `sync` (`Pull` without its watchdog)."""
    w = advance(steps, None, _not_yet, before_wait)
    while w is not None:
        w[0].sync(w[1])
        w = advance(steps, w, _not_yet, before_wait)


class Reactor:
    """Drive a lockstep loop from the transport's receive callbacks.

    The loop runs on the thread that delivers the frame it was waiting for,
    so a frame in and the frames it causes out take no thread hand-over: on
    the 2-core machine a hand-over (futex wake-up, context switch) costs
    about as much CPU as the message itself. The main thread only waits for
    the end and bounds every wait: a link silent for `timeout` seconds of
    wall time is given up (wall time detects failures only, never behaviour).
    """

    cooperative = False
    watchdog = None  # it bounds the waits itself, in `run`
    cpu_s = staticmethod(own_cpu_s)

    def __init__(
        self,
        timeout: float,
        announce: Callable[[int | None], None] | None = None,
        upstream_waited: Callable[[str, int], float | None] | None = None,
        clock: Clock = MONOTONIC,
    ):
        self.timeout = timeout
        self.clock = clock  # wall time, for failure detection only
        # A wait longer than `announce_after` is announced (a liveliness token naming the tick this
        # process is about to act at). A sender owes the frame we miss only since it was last seen
        # announcing a wait of its own at a tick not past that frame (`upstream_waited`: the
        # monotonic time, now while it still announces one): before, it was stalled upstream, not at
        # fault. So only the process whose sender owes a frame gives up.
        # Counting from the start of our own wait instead blamed a sender that had just moved on
        # from one stalled wait to the next: its new wait is announced only `announce_after` later.
        self._announce = announce
        self._upstream_waited = upstream_waited
        self.announce_after = min(1.0, timeout / 4)
        self._announced: int | None = None
        self.lock = threading.Lock()
        self.done = threading.Event()
        self._steps: Waits | None = None
        self._waiting: Wait | None = None
        self._since = 0.0
        self.error: BaseException | None = None
        self.before_wait: Callable[[], None] | None = None  # called as the loop starts to wait on a link not `paired`
        self.on_idle: Callable[[], None] | None = None  # called on the main thread at each look

    def connect(
        self, ib: Inbound[Any], transport: Transport, verify: Verify | None, on_forged: Callable[[], None]
    ) -> None:
        transport.subscribe_callback(ib.key, functools.partial(self.on_frame, ib), verify, on_forged)

    def on_frame(self, ib: Inbound[Any], raw: bytes) -> None:
        with self.lock:
            ib.feed(raw)
            if self._steps is not None:
                self._advance()

    def poke(self) -> None:
        """Look again at what the loop waits for: something other than a frame (a pacer's
        clock or a viewer's control, runtime/pace.py) may have made it ready."""
        with self.lock:
            if self._steps is not None:
                self._advance()

    @staticmethod
    def _settle(ib: Inbound[Any], k: int) -> bool:  # `advance`'s settle
        # As in `Inbound.sync`: a wake-up while we wait for a gone sender.
        if ib.woken and ib.sender_gone():
            ib.give_up("its liveliness token vanished")
            return True
        ib.woken = False
        return False

    def _advance(self) -> None:
        try:
            was = self._waiting
            self._waiting = advance(self._steps, was, self._settle, self.before_wait)  # type: ignore[arg-type]
            if self._waiting is None:
                self._finish()
            elif self._waiting is not was:
                self._since = self.clock.monotonic()  # the start of this wait
        except BaseException as exc:  # raised again on the main thread by `run`
            self.error = exc
            self._finish()

    def _finish(self) -> None:
        self._steps = None
        self._waiting = None
        self.done.set()

    def drive(self, steps: Waits, before_wait: Callable[[], None] | None = None) -> Waits:
        self.before_wait = before_wait
        self.run(steps)
        yield from ()

    def run(self, steps: Waits) -> None:
        """Start the loop here, then wait for it to end on the callbacks' thread."""
        with self.lock:
            self._steps = steps
            self._advance()
        while not self.clock.wait(self.done, 0.1):
            if self.on_idle is not None:
                self.on_idle()
            self._look()
        self._set_announced(None)
        if self.error is not None:
            raise self.error

    def _look(self) -> None:
        """One look from the main thread: announce a long wait, give up on a link silent past the timeout."""
        with self.lock:
            waited = self.clock.monotonic() - self._since
            want = self._waiting[1] if self._waiting is not None and waited >= self.announce_after else None
        self._set_announced(want)
        with self.lock:
            if self._waiting is None:
                return
            ib, k = self._waiting
            now = self.clock.monotonic()
            if now - self._since < self.timeout:
                return
            missing = ib.schedule.first_after(ib.last_seen)
            waited = None if self._upstream_waited is None else self._upstream_waited(ib.sender, missing)
            if waited is not None and now - waited < self.timeout:
                # Its sender waits for its own upstream, or did until lately: it owes the frame
                # only since then. Asked again at the next look; our own wait stays announced
                # (resetting `_since` here took our token back for `announce_after`).
                return
            ib.give_up(f"silent for {self.timeout:g} s waiting for tick {k}")
            self._advance()

    def _set_announced(self, tick: int | None) -> None:
        """Announce the wait before acting at `tick` (None: no wait worth announcing). Main thread only."""
        if self._announce is None or tick == self._announced:
            return
        self._announce(tick)
        self._announced = tick

    def close(self) -> None:
        pass


class WaitBoard:
    """The waits this process and its peers announce (`waiting/<process>/<tick>` liveliness
    tokens), which the `Reactor` blames a silent peer by: a peer that announces waiting
    before acting at a tick owes none of the frames after it yet."""

    def __init__(self, transport: ZenohTransport, keys: Keys, name: str, clock: Clock = MONOTONIC):
        self._transport = transport
        self._clock = clock  # the `Reactor`'s: the times it hands back are compared with its own
        self._keys = keys
        self._name = name
        self._lock = threading.Lock()
        self._waits: dict[str, set[int]] = {}  # peer -> the ticks it announces waiting before
        self._waited: dict[str, dict[int, float]] = {}  # peer -> tick -> when it took that announcement back
        self._token: Callable[[], None] | None = None
        transport.watch_alive(keys.waiting_all(), self.on_waiting)

    def on_waiting(self, key: str, alive: bool) -> None:
        peer, _, text = key.split(f"/{WAITING}/", 1)[-1].rpartition("/")
        if not text.isdigit():
            return  # not a token this runtime declares: ignored
        tick = int(text)
        with self._lock:
            ticks = self._waits.setdefault(peer, set())
            if alive:
                ticks.add(tick)
            else:
                ticks.discard(tick)
                # Wall time for failure detection only: from here on it may owe its frames.
                self._waited.setdefault(peer, {})[tick] = self._clock.monotonic()

    def upstream_waited(self, peer: str, missing: int) -> float | None:
        """When `peer` was last seen blocked itself, before acting at a tick not past `missing`
        (it owed us nothing then): now while it still announces such a wait, the monotonic time
        it took the last one back otherwise, None if it never announced one."""
        with self._lock:
            if any(s <= missing for s in self._waits.get(peer, ())):
                return self._clock.monotonic()
            return max((t for s, t in self._waited.get(peer, {}).items() if s <= missing), default=None)

    def announce(self, tick: int | None) -> None:
        """Announce this process's own wait before acting at `tick` (None: take it back)."""
        if self._token is not None:
            self._token()
            self._token = None
        if tick is not None:
            self._token = self._transport.declare_token(self._keys.waiting(self._name, tick))

    def reactor(self, timeout: float) -> Reactor:
        """A `Reactor` that announces its long waits here and blames by what the peers announce."""
        return Reactor(timeout, self.announce, self.upstream_waited, self._clock)
