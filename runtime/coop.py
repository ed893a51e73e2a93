"""Cooperative lockstep: every node of a match in ONE thread, no locks.

Each node's lockstep loop is a generator that yields `(inbound, k)` where it
needs that link's frames due at tick k (runtime/lockstep.py). Each node's
driver is a `Task` (a `Driver`, runtime/drivers.py), and `play` runs every
node's `Node.playing()` at once: `drive` resumes each one with the drivers'
shared `advance` as long as the link it waits on is `ready(k)`, and parks it
otherwise. Frames are the very msgpack bytes a real match sends, on the
in-memory bus (`CoopBus`, a `MemoryBus` without locks), and they are accepted
by the same `Inbound` code in the same order, so every process's digest is the
one of the distributed run. A link takes each frame in as it is put, in the
sender's turn (`CoopLink`), and a frame that makes the link a parked node
waits on ready makes that node runnable again.

Nothing blocks, so nothing needs a watchdog thread: when no node is runnable
and some have not finished, every unfinished node waits on another one, a
deadlock. Where the distributed run's watchdog would give up on a silent link
after `wait_timeout` of wall time, `drive` gives up on the links the parked
nodes wait on at once, with a logged reason; their senders are then recorded
in `dead` as in the distributed run, and the match goes on.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from arena.runtime.drivers import Wait, advance, subscribe
from arena.runtime.lockstep import BATCH_HEADS, Inbound, Waits
from arena.runtime.transport import WAKE, MemoryBus, MemoryTransport
from arena.schemas.keys import MAX_FRAME_BYTES
from arena.schemas.messages import Summary

if TYPE_CHECKING:
    from arena.runtime.node import Node


class WouldBlock(RuntimeError):
    """A node tried to block in `recv` on the cooperative bus (only `drive` may wait)."""


class CoopChannel:
    """A subscription: a deque, and the parked task (if any) to wake on the next frame."""

    __slots__ = ("_q", "waiter", "_wake")

    def __init__(self, wake: Callable[[Task], None]):
        self._q: deque[bytes] = deque()
        self.waiter: Task | None = None
        self._wake = wake

    def put(self, payload: bytes) -> None:
        self._q.append(payload)
        w = self.waiter
        if w is not None:
            self.waiter = None
            self._wake(w)

    def try_recv(self) -> bytes | None:
        q = self._q
        return q.popleft() if q else None

    def recv(self) -> bytes:
        if self._q:
            return self._q.popleft()
        raise WouldBlock("recv on an empty channel in a cooperative match (lockstep only; no --realtime)")


class CoopLink:
    """A lockstep link's subscription (`Task.connect`): a frame put is taken in by its `Inbound` at
    once, in the sender's turn, as a `Reactor` takes it in from a receive callback; its parked task
    (if any) is woken only once the link is ready for the tick it waits on (by the `Inbound`, `link`).

    Taking a frame in early is what a distributed receiver does whenever the network is quick: a
    frame not yet due is held by the link (`Inbound.take`), so the digests are those of draining a
    queue at each wait, without the queue (a deque, its drain and two `try_recv` per frame)."""

    __slots__ = ("_ib", "_accept", "_one", "waiter", "_wake")

    def __init__(self, ib: Inbound[Any], wake: Callable[[Task], None]):
        self._ib = ib
        self._accept = ib._accept_frame
        self._one = ib._accept_one
        self.waiter: Task | None = None
        self._wake = wake

    def put(self, payload: bytes) -> None:
        """What else is put on the key (`CoopBus.deliver`: a replay's recorded frames, a WAKE): scanned
        for every float header. A frame taken in wakes the parked task itself (`Inbound._accept_one`)."""
        if payload == WAKE:  # `Inbound.feed`, inlined
            self._ib.woken = True
        elif payload and payload[0] not in BATCH_HEADS and len(payload) <= MAX_FRAME_BYTES:
            self._one(payload, None, False)  # what `_accept_frame` does with one frame: one call less a frame
        else:
            self._accept(payload, None)

    def own(self) -> Callable[[bytes], None]:
        """What a publisher of this process puts with (`CoopBus.putter`): `Inbound._accept_one(raw)`,
        for an `Outbound`'s frame (float64s only: a cheaper scan), never a WAKE; it wakes the parked
        task itself. Straight there: one Python call a frame from `Outbound.send`, not two."""
        return self._ib._accept_one

    def try_recv(self) -> bytes | None:
        return None  # every frame was taken in as it was put

    def recv(self) -> bytes:
        raise WouldBlock("recv on a cooperative link (lockstep only; no --realtime)")


def _own_put(ch: CoopChannel | CoopLink) -> Callable[[bytes], None]:
    """What a publisher of this process puts into `ch` with (`CoopLink.own`)."""
    return ch.own() if type(ch) is CoopLink else ch.put


class CoopBus(MemoryBus):
    """The in-memory bus of one cooperative match: no locks, delivery targets cached per key."""

    def __init__(self) -> None:
        super().__init__()
        self.runnable: deque[Task] = deque()
        self._targets: dict[str, list[tuple[object, CoopChannel | CoopLink]]] = {}
        self._puts: dict[str, list[Callable[[bytes], None]]] = {}  # key -> its targets' `put`s (`putter`)
        self._putters: dict[Callable[[bytes], None], str] = {}  # every `putter` handed out -> its key
        # key -> (holder, putter, target): a holder whose `_put` was set to the key's one target (`straighten`)
        self._straight: dict[str, list[tuple[Any, Callable[[bytes], None], Callable[[bytes], None]]]] = {}

    def _targets_of(self, key: str) -> list[tuple[object, CoopChannel | CoopLink]]:
        targets = self._targets.get(key)
        if targets is None:
            targets = self._targets[key] = [
                (owner, ch) for expr, subs in self._subs.items() if self.matches(expr, key) for owner, ch in subs
            ]
        return targets

    def deliver(self, key: str, payload: bytes, only: object | None = None) -> None:
        for owner, ch in self._targets_of(key):
            if only is None or owner is only:
                ch.put(payload)

    def putter(self, key: str) -> Callable[[bytes], None]:
        """`deliver(key, payload)` for a publisher: its targets looked up once, kept current as others subscribe."""
        puts = self._puts.get(key)
        if puts is None:
            puts = self._puts[key] = [_own_put(ch) for _, ch in self._targets_of(key)]

        def put(payload: bytes) -> None:
            for p in puts:
                p(payload)

        self._putters[put] = key
        return put

    def straighten(self, outbound: Iterable[Any]) -> None:
        """Let each of `outbound` (an `Outbound`, or what it puts through: `Latest`, `WireGate`) whose
        key has one target now put straight into that target, not through its `putter`'s loop: one
        call less a frame. A later subscriber to that key puts the putter back (`_subscribed`)."""
        for holder in outbound:
            while (put := getattr(holder, "_put", None)) is not None and put not in self._putters:
                holder = put  # a wrapper: what it puts through
            if put is None:
                continue
            key = self._putters[put]
            puts = self._puts[key]
            if len(puts) == 1:
                holder._put = puts[0]
                self._straight.setdefault(key, []).append((holder, put, puts[0]))

    def _subscribed(self, owner: object, key: str, ch: CoopChannel | CoopLink) -> None:
        self._subs[key].append((owner, ch))  # type: ignore[arg-type]
        for k in [k for k in self._targets if self.matches(key, k)]:
            del self._targets[k]
            for holder, put, target in self._straight.pop(k, ()):
                if holder._put is target:  # (not muted since: `Outbound.mute`)
                    holder._put = put
            puts = self._puts.get(k)
            if puts is not None:  # in place: the publishers' `put`s hold these lists
                puts[:] = [_own_put(c) for _, c in self._targets_of(k)]

    def subscribe(self, owner: object, key: str) -> CoopChannel:  # type: ignore[override]
        ch = CoopChannel(self.runnable.append)
        self._subscribed(owner, key, ch)
        return ch

    def link(self, owner: object, ib: Inbound[Any]) -> CoopLink:
        """Subscribe `ib` to its key: every frame put there is taken in at once (`CoopLink`)."""
        # A task its frame makes ready runs next (the front of the run queue): a consumer takes what
        # its producer just sent before others run on, which leaves it fewer waits that park it
        # (3.78 -> 3.42 parks a tick, BD v BS). Any order gives the same frames and digests.
        ch = CoopLink(ib, self.runnable.appendleft)
        ib.link = ch  # its frames wake the task parked on `ch` (`Inbound._accept_one`)
        self._subscribed(owner, ib.key, ch)
        return ch


def connect(ib: Inbound[Any], transport: MemoryTransport, verify: object, on_forged: object) -> None:
    """`Driver.connect` of a cooperative match: `ib` takes each frame in as it is put (`CoopLink`).
    No MAC on the in-memory bus: its frames come from this process's own nodes. On a plain
    `MemoryBus` (no `link`), a channel as any driver's (`subscribe`), drained at each wait."""
    link = getattr(getattr(transport, "bus", None), "link", None)
    if link is None:
        subscribe(ib, transport, verify, on_forged)  # type: ignore[arg-type]
        return
    ib.channel = link(transport, ib)


class Task:
    """One node's driver in a cooperative match (`Node(driver=Task(name))`), and its loop as
    `drive` sees it. A `Driver` (runtime/drivers.py) whose `drive` hands the loop's waits to
    the scheduler; the start barrier is skipped: every node is there by construction."""

    __slots__ = ("name", "steps", "flush", "waiting", "done", "busy_s", "summary", "node")

    cooperative = True
    watchdog = None  # nothing blocks: a deadlock is detected by `drive`, not waited out
    connect = staticmethod(connect)

    def __init__(self, name: str, steps: Waits | None = None, flush: Callable[[], None] | None = None):
        self.name = name
        self.steps = steps
        self.flush = flush  # called as the task parks on a link not `paired` (`Node.batch_flusher`)
        self.waiting: Wait | None = None
        self.done = False
        # Wall seconds spent inside this node's loop (one thread: its CPU share), with what its
        # receivers did to take in its frames (`CoopLink`).
        self.busy_s = 0.0
        self.summary: Summary | None = None  # what `play` played to its end returned
        self.node: Node | None = None  # the node it plays (`play`)

    def drive(self, steps: Waits, before_wait: Callable[[], None] | None) -> Waits:
        # The loop itself, not a generator round it: one level less for each of its resumes.
        self.flush = before_wait
        return steps

    def before_wait(self) -> None:
        # Looked up at each park: `drive` sets it once the node's loop starts.
        if self.flush is not None:
            self.flush()

    def cpu_s(self) -> list[float]:
        return [round(self.busy_s, 3), 0.0]

    def close(self) -> None:
        pass

    def play(self, node: Node) -> None:
        """Play `node`'s match (`Node.playing`): `steps` is its generator itself, not one delegating to
        it (each level of `yield from` costs every resume a frame entry), and `summary` is what the
        node `concluded` once its loop has ended (`end`)."""
        self.node = node
        self.steps = node.playing()

    def end(self) -> None:
        """The loop has ended: the task is done, with its node's summary (if it plays one)."""
        self.done = True
        if self.node is not None:
            self.summary = self.node.concluded


class NodeFailed(RuntimeError):
    """A node's loop raised; the message names the node."""

    def __init__(self, name: str, exc: BaseException):
        super().__init__(f"{name} failed: {type(exc).__name__}: {exc}")
        self.name = name


def _drained(ib: Inbound[Any], k: int) -> bool:
    """`advance`'s last look: take in what arrived on the link's channel (a `CoopLink` took
    every frame in as it was put: nothing to look at)."""
    if type(ib.channel) is CoopLink:
        return False
    ib.drain()
    return ib.ready(k)


def _advance(task: Task) -> None:
    """Run `task` until it waits on a link that is not ready (parked on its channel), or ends."""
    w = task.waiting  # once its loop has started, the node's flusher itself, as `drive` passes it
    task.waiting = advance(task.steps, w, _drained, task.before_wait if w is None else task.flush)  # type: ignore[arg-type]
    if task.waiting is None:
        task.end()
    else:
        task.waiting[0].channel.waiter = task  # type: ignore[union-attr]


def play(
    bus: CoopBus,
    nodes: Iterable[Node],
    on_idle: Callable[[], None] | None = None,
    quit_early: set[str] | None = None,
    meant_to_end: frozenset[str] = frozenset(),
) -> tuple[dict[str, Summary], list[str]]:
    """Play every node's match (`Node.playing`: loop and summary) at once, each driven by its
    `Task`; returns their summaries by name and the deadlocks met (`drive`)."""
    tasks: list[Task] = []
    for node in nodes:
        task = node.driver
        assert isinstance(task, Task), f"{node.name}: a cooperative match's nodes are driven by a coop.Task"
        task.play(node)
        tasks.append(task)
    deadlocks = drive(bus, tasks, on_idle=on_idle, quit_early=quit_early, meant_to_end=meant_to_end)
    return {t.name: t.summary for t in tasks if t.summary is not None}, deadlocks


def drive(
    bus: CoopBus,
    tasks: list[Task],
    on_idle: Callable[[], None] | None = None,
    quit_early: set[str] | None = None,
    meant_to_end: frozenset[str] = frozenset(),
) -> list[str]:
    """Run every task to its end; returns the deadlocks met (one line each), usually none.

    `quit_early` collects the nodes whose loop ended while others still waited
    for them (what a launcher would see as a vanished liveliness token). Waits
    given up only on nodes in `meant_to_end` (a scenario's `kill` step) are no
    deadlock: they are not listed.

    `on_idle` is called whenever the run queue has gone round once (the
    recorder drains its taps there). A task that raises ends the match:
    `NodeFailed` names it.
    """
    runnable = bus.runnable
    runnable.extend(tasks)
    deadlocks: list[str] = []
    clock = time.perf_counter
    while True:
        n = len(runnable)
        t0 = clock()
        for _ in range(n):
            task = runnable.popleft()
            if task.done:
                continue
            try:  # `_advance(task)`, inlined: one call less a resume
                # Once its loop has started (a wait given back), what `before_wait` calls is known: the
                # node's flusher, None (most in process: nothing batched) saving a call every park.
                w = task.waiting
                task.waiting = w = advance(task.steps, w, _drained, task.before_wait if w is None else task.flush)  # type: ignore[arg-type]
                if w is None:
                    task.end()
                else:
                    w[0].channel.waiter = task  # type: ignore[union-attr]
            except Exception as exc:
                raise NodeFailed(task.name, exc) from exc
            # Since the previous resume ended (its pop and look too): one clock read a resume, not two.
            t1 = clock()
            task.busy_s += t1 - t0
            t0 = t1
        if on_idle is not None:
            on_idle()
        if runnable:
            continue
        parked = [t for t in tasks if not t.done and t.waiting is not None]
        if not parked:
            return deadlocks
        # Waits on a node whose loop has ended are given up first: in a distributed
        # match its liveliness token would be gone. Only a cycle of live nodes is
        # ended as the watchdog would end it after `wait_timeout`: every wait at once.
        live = {t.name for t in tasks if not t.done}
        stuck = [t for t in parked if t.waiting[0].sender not in live] or parked  # type: ignore[index]
        if not all(t.waiting[0].sender in meant_to_end - live for t in stuck):  # type: ignore[index]
            waits = ", ".join(f"{t.name} on {t.waiting[0].key} (tick {t.waiting[1]})" for t in parked)  # type: ignore[index]
            deadlocks.append(f"deadlock: every unfinished node waits: {waits}")
        for t in stuck:
            ib, k = t.waiting  # type: ignore[misc]
            ib.channel.waiter = None  # type: ignore[union-attr]
            why = "its loop ended" if ib.sender not in live else f"nobody can send tick {k}"
            if ib.sender not in live and quit_early is not None:
                quit_early.add(ib.sender)
            ib.give_up(f"deadlock: {why} (cooperative driver)")
            runnable.append(t)


def run_runnable(bus: CoopBus) -> None:
    """Resume runnable tasks until none is, then return: one stretch of a driver that
    pauses the match between stretches (`arena.learn` stops where a learner needs an
    action; a task parked on something the caller releases is woken by putting it on
    `bus.runnable`). `drive` runs to the end instead. A task that raises: `NodeFailed`."""
    runnable = bus.runnable
    while runnable:
        task = runnable.popleft()
        if task.done:
            continue
        try:
            _advance(task)
        except Exception as exc:
            raise NodeFailed(task.name, exc) from exc
