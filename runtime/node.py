"""What every process of a match shares: identity, wiring, barrier, summary.

Two shapes of process:

* a `Node` takes part in the lockstep: it declares its links in `__init__`
  with `out(...)` and `inp(...)`, and implements `lockstep()` (and
  `loop_realtime()`); a `Driver` (runtime/drivers.py) runs that loop;
* an `Observer` (the recorder, the viewer) is in nobody's lockstep and has
  none of its own: it implements `observe()`.

`play()` then does the rest, the same for both and under every driver:

1. declares the liveliness token `arena/<m>/alive/<process>` *after* every
   subscription, so a peer that sees the token can already reach it;
2. waits (bounded) until every process of the match has its token (not under
   the cooperative driver, where every node is there by construction);
3. runs the loop (`loop()`);
4. publishes its `Summary` (digest, counters, link statistics).
"""

from __future__ import annotations

import contextlib
import functools
import gc
import hashlib
import logging
import os
import threading
import time
from collections.abc import Callable, Generator, Iterator
from typing import Any, TypeVar

from arena.config import MatchConfig, ProcessId
from arena.runtime import seeds
from arena.runtime.clock import MONOTONIC, Clock
from arena.runtime.drivers import Driver, Pull, Reactor, Wait, own_cpu_s
from arena.runtime.links import IDEAL, LinkEmulator, resolve, scheduled
from arena.runtime.lockstep import Inbound, Latest, Outbound, Rejections, Schedule, Waits
from arena.runtime.mac import Keyring
from arena.runtime.stats import percentile
from arena.runtime.tap import Handoff, Tap, TappedOutbound
from arena.runtime.transport import Transport, Verify
from arena.schemas import messages as msgs
from arena.schemas.keys import KEY_BY_NAME, SERVED, Keys

M = TypeVar("M", bound=msgs.Base)


def settle_heap() -> None:
    """Everything built so far lives for the whole match: keep it out of the
    collector's way (the tick loop allocates only short-lived, acyclic objects
    that reference counting frees). A process of its own calls it before its first tick."""
    gc.collect()
    gc.freeze()
    gc.set_threshold(50_000, 50, 100)


@contextlib.contextmanager
def match_heap(collect: bool = True) -> Iterator[None]:
    """`settle_heap` for a match played among its caller's objects (the in-process engine).

    The caller's heap is frozen as it is, after a young collection only: a full one scanned all
    of it before every match, ~40 ms in a process with matplotlib loaded, a fifth of a 2 x 4 s
    match. The match's own objects are built after the freeze and stay the collector's, so one
    full collection at the end, which scans only them, frees the cycles the match leaves; then
    the caller's heap is the collector's again. `collect=False`: a process that ends with the match
    (`arena match`) skips that collection (~14 M instructions), its exit frees nothing either.
    """
    gc.collect(1)
    gc.freeze()
    gc.set_threshold(50_000, 50, 100)
    try:
        yield
    finally:
        if collect:
            gc.collect()
        gc.unfreeze()


class StartupError(RuntimeError):
    """The match could not start: a process never came up."""


class Peer:
    """One process of a match: identity, keys, the start barrier, liveliness, the summary.

    A subclass is a `Node` (in the lockstep) or an `Observer` (outside it).
    """

    # slots (a subclass adds its own): an instance dict of 30 keys or more loses CPython 3.11's shared keys,
    # and every method call on the instance then costs ~250 instructions more
    __slots__ = (
        "pid clock name cfg transport keys log keyring digest rejections silent outbound inbound gone dead "
        "dead_at _alive _alive_cond _work_s last_tick _wall_s play_started _collector on_waiting tap "
        "_tap_handoff _spoofing_tokens concluded __dict__"
    ).split()

    cooperative = False  # True: played by a cooperative scheduler (runtime/drivers.py `Driver`)

    def __init__(self, pid: ProcessId, cfg: MatchConfig, transport: Transport, keys: Keys, clock: Clock = MONOTONIC):
        self.pid = pid
        self.clock = clock  # wall time for the start barrier's bound (runtime/clock.py)
        self.name = str(pid)
        self.cfg = cfg
        self.transport = transport
        self.keys = keys
        self.log = logging.getLogger(f"arena.{self.name}")
        # This process's MAC key and the keys of the senders it verifies (runtime/mac.py);
        # the transport carries them because they come with the session's credentials.
        self.keyring: Keyring = getattr(transport, "keyring", None) or Keyring(self.name)
        self.digest = hashlib.blake2b(digest_size=16)
        self.rejections = Rejections(self.log)
        self.silent: dict[str, int] = {}  # peers given up on while alive and not waiting themselves
        self.outbound: list[Outbound[Any]] = []
        self.inbound: list[Inbound[Any]] = []
        self.gone: set[str] = set()  # peers whose liveliness token vanished
        self.dead: dict[str, str] = {}  # peers we stopped waiting for, with the reason
        self.dead_at: dict[str, int] = {}  # ... and our tick when we did
        self._alive: set[str] = set()
        self._alive_cond = threading.Condition()
        self._work_s: list[float] = []  # wall seconds of own work per tick (perf statistics only)
        self.last_tick = 0
        self._wall_s = 0.0
        self.play_started = 0.0  # [s] Unix time of the start of the loop (start-up measurement only)
        self.concluded: msgs.Summary | None = None  # what `playing` returned, once it has
        self._collector = False
        # Called with the peers still missing, once a wait at the start barrier
        # passes 1 s and whenever that list changes (`arena run` by hand prints it).
        self.on_waiting: Callable[[list[str]], None] | None = None
        self.tap: Tap | None = None  # a `Node`'s, in a recorded match
        self._tap_handoff: Handoff | None = None
        self._spoofing_tokens: list[object] = []  # `announce_spoofing`

    def announce_spoofing(self) -> None:
        """Declare `spoofing/<user>/<key>` for every key first found spoofed since the last call
        (a forged or conflicting frame, `Rejections`), so the launcher says so during the match.
        Main thread only: a zenoh session call from its own callback thread can collide with it."""
        new = self.rejections.spoofed_new
        declare = getattr(self.transport, "declare_token", None)
        while new:
            key = new.pop(0)
            if declare is not None:
                self._spoofing_tokens.append(declare(self.keys.spoofing(self.name, self.keys.rel(key))))

    def mac_check(self, key: str, sender: str) -> tuple[Verify | None, Callable[[], None]]:
        """(verify, on_forged) for what `sender` puts on `key` (or answers there): only its frames,
        by their MAC (runtime/mac.py; None: no key for it, accept all); each other one counted per key
        as forged and, the first, announced (`Rejections.forged`)."""
        return self.keyring.verifier(sender, key), functools.partial(self.rejections.forged, key, sender)

    def rng(self, *path: object):
        """This process's own RNG for `path` (one per component)."""
        return seeds.rng(self.cfg.seed, self.name, *path)

    # -------------------------------------------------------------- liveliness
    def _is_gone(self, peer: str) -> bool:
        return peer in self.gone

    def _record_dead(self, peer: str, why: str) -> None:
        if peer not in self.dead:
            self.dead[peer] = why
            self.dead_at[peer] = self.last_tick
            meant = killed_at(self.cfg, peer) >= 0  # a scenario's `kill` step: expected, so not an error
            self.log.log(logging.INFO if meant else logging.ERROR, "treating %s as dead: %s", peer, why)
            if " silent for " in why:
                self.silent[peer] = self.last_tick
            self.on_peer_dead(peer)

    def on_peer_dead(self, peer: str) -> None:
        """Hook: a peer we were waiting for is dead (its inputs no longer come)."""

    def _on_collector(self, key: str, alive: bool) -> None:
        self._collector = alive

    def _on_alive(self, key: str, alive: bool) -> None:
        peer = key.split("/alive/", 1)[-1]
        with self._alive_cond:
            if alive:
                self._alive.add(peer)
                self.gone.discard(peer)
            else:
                self._alive.discard(peer)
                self.gone.add(peer)
            self._alive_cond.notify_all()
        if not alive:
            for ib in self.inbound:
                if ib.sender == peer:
                    self.transport.wake(ib.key)

    def expected_peers(self) -> list[str]:
        return [str(p) for p in self.cfg.processes()]

    def barrier(self) -> None:
        self.transport.watch_alive(self.keys.collector(), self._on_collector)
        self.transport.watch_alive(self.keys.alive_all(), self._on_alive)
        self.transport.declare_alive(self.keys.alive(self.name))
        expected = set(self.expected_peers())
        clock = self.clock
        start = clock.monotonic()
        deadline = start + self.cfg.timing.startup_timeout
        told: list[str] | None = None
        with self._alive_cond:
            # A peer whose token came and went is no one to wait for: it started and died (a robot whose
            # policy failed at tick 0); the loop treats it as dead. Waiting would blame this process.
            while not expected <= self._alive | self.gone:
                missing_now = sorted(expected - self._alive - self.gone)
                if self.on_waiting is not None and missing_now != told and clock.monotonic() - start > 1.0:
                    told = missing_now
                    self.on_waiting(missing_now)
                left = deadline - clock.monotonic()
                if left <= 0:
                    missing = ", ".join(sorted(expected - self._alive - self.gone))
                    raise StartupError(
                        f"{self.name}: gave up after {self.cfg.timing.startup_timeout:g} s waiting for: {missing}"
                    )
                clock.wait_on(self._alive_cond, min(left, 0.5))
                self._alive_cond.release()  # a session call, and not under the lock its callbacks take
                try:
                    self.announce_spoofing()  # forged frames come in at the barrier too: said as they do
                finally:
                    self._alive_cond.acquire()
        if self.tap is not None:
            # Through a router (client mode), a peer's liveliness token can arrive
            # before its subscriber declaration: the first tap batch would be
            # filtered out at the source. Start once the recorder is matched.
            tap_key = self.keys.tap(self.name)
            while not self.transport.has_subscribers(tap_key) and clock.monotonic() < deadline:
                clock.sleep(0.01)
        if told is not None and self.on_waiting is not None:
            self.on_waiting([])
        self.announce_spoofing()  # frames come in at the barrier too, forged ones included

    # ------------------------------------------------------------------- play
    def loop(self) -> Waits:
        """The match itself, between the barrier and the summary (a `Node`'s lockstep, an `Observer`'s watch)."""
        raise NotImplementedError

    def playing(self) -> Generator[Wait, None, msgs.Summary]:
        """`play`, as a generator: it yields the waits of a cooperative driver's loop (runtime/coop.py
        `play`); under a blocking driver it yields nothing. Returns the Summary."""
        try:
            if not self.cooperative:  # under the cooperative driver its runner settles the heap (`match_heap`)
                self.barrier()
                settle_heap()
            self.play_started = time.time()
            t0 = time.perf_counter()
            yield from self.loop()
            self._wall_s = time.perf_counter() - t0
        finally:
            self.close()
        self.concluded = summary = self.conclude()
        return summary

    def play(self) -> msgs.Summary:
        """This process's whole match: the start barrier, the loop, the summary (published and returned)."""
        steps = self.playing()
        try:
            next(steps)
        except StopIteration as end:
            return end.value
        steps.close()
        raise RuntimeError(f"{self.name}: a cooperative driver's node is played by its scheduler (runtime/coop.py)")

    def close(self) -> None:
        """After the loop, whatever happened in it: stop what the loop needed (threads, servers)."""

    def cpu_s(self) -> list[float]:
        """[user, system] CPU seconds this process took (the summary's `cpu_s`)."""
        return own_cpu_s()

    def summary_extra(self) -> dict[str, object]:
        return {}

    def conclude(self) -> msgs.Summary:
        """After the loop: the tap's final batch, then the Summary, published and returned."""
        if not self.cooperative:
            self.announce_spoofing()
        if self.tap is not None:
            self.tap.close(self.last_tick)
            if self._tap_handoff is not None:
                self._tap_handoff.close()
        summary = self.summary()
        self.deliver_summary(msgs.encode(summary))
        return summary

    def deliver_summary(self, payload: bytes, timeout: float = 5.0) -> None:
        """Publish the summary until a collector acknowledges it (bounded).

        A process that closes its session right after a put can lose that
        put; when a collector (`arena match`, `arena up`) is present, it
        acknowledges every summary on `ack/<process>`. With no collector
        (a process started on its own) nobody waits.
        """
        ack = self.transport.subscribe(self.keys.ack(self.name))
        put = self.transport.publisher(
            self.keys.summary(self.name), sign=self.keyring.signer(self.keys.summary(self.name))
        )
        clock = self.clock
        deadline = clock.monotonic() + timeout
        while True:
            put(payload)
            if not self._collector:
                return
            wait_until = min(deadline, clock.monotonic() + 0.25)
            while clock.monotonic() < wait_until:
                if ack.try_recv() is not None:
                    return
                clock.sleep(0.005)
            if clock.monotonic() >= deadline:
                self.log.warning("no collector acknowledged the summary within %g s", timeout)
                return

    def timed(self, start: float) -> None:
        """Record the wall time of one tick's own work (for the timing statistics)."""
        self._work_s.append(time.perf_counter() - start)

    def summary(self) -> msgs.Summary:
        links: dict[str, dict[str, float]] = {}
        delays: dict[str, list[float]] = {}
        for ib in self.inbound:
            frames, dropped, kept = ib.counted()
            agg = links.setdefault(ib.link_class, {"frames": 0.0, "dropped": 0.0})
            agg["frames"] += frames
            agg["dropped"] += dropped
            delays.setdefault(ib.link_class, []).extend(round(d, 3) for d in kept)
        tick_us: list[float] = []
        if self._work_s:
            w = sorted(self._work_s)
            tick_us = [percentile(w, 50) * 1e6, percentile(w, 95) * 1e6]
        return msgs.Summary(
            tick=self.last_tick,
            process=self.name,
            pid=os.getpid(),
            digest=self.digest.hexdigest(),
            sent=sum(o.sent for o in self.outbound),
            rejected=self.rejections.total,
            rejected_reasons=dict(self.rejections.by_reason),
            links=links,
            delays_ms=delays,
            dead=sorted(self.dead),
            tick_us=tick_us,
            wall_s=self._wall_s,
            cpu_s=self.cpu_s(),
            extra={
                **self.summary_extra(),
                "play_started": self.play_started,
                **({"silent": dict(self.silent)} if self.silent else {}),
            },
            sent_by_key={o.rel.decode(): o.sent for o in self.outbound},
            conflicts={self.keys.rel(k): n for k, n in sorted(self.rejections.conflicts.items())},
            dead_at=dict(sorted(self.dead_at.items())),
            forged={self.keys.rel(k): n for k, n in sorted(self.rejections.forged_by_key.items())},
        )


class Node(Peer):
    """A process in the lockstep: its links, its lockstep loop, and the `Driver` that runs it.

    `driver`: `Pull` (blocking on this thread) unless given; a zenoh match in lockstep
    gives a `Reactor` (match/run.py), a cooperative match a `coop.Task`.
    """

    # slots: see `Peer`
    __slots__ = "driver links skip_below".split()

    def __init__(
        self,
        pid: ProcessId,
        cfg: MatchConfig,
        transport: Transport,
        keys: Keys,
        driver: Driver | None = None,
        clock: Clock = MONOTONIC,
    ):
        super().__init__(pid, cfg, transport, keys, clock)
        self.driver: Driver = driver if driver is not None else Pull(transport, cfg.timing.wait_timeout, clock)
        self.cooperative = self.driver.cooperative
        self.links = resolve(cfg.link, cfg.link_overrides)
        # A recorded match: everything this process sends also goes to its tap
        # (runtime/tap.py), which the recorder collects. A `Reactor` runs the loop on
        # the transport's receive thread, where a large put must not block: a `Handoff`.
        if cfg.tap:
            put = transport.publisher(keys.tap(self.name), sign=self.keyring.signer(keys.tap(self.name)))
            self._tap_handoff = Handoff(put) if isinstance(self.driver, Reactor) else None
            self.tap = Tap(self.name, self._tap_handoff or put)
        if isinstance(self.driver, Reactor):  # its main thread looks ten times a second
            self.driver.on_idle = self.announce_spoofing
        # A lockstep loop may skip yielding a wait at tick k < skip_below whose link is
        # `ready(k)` already, noting `waited` itself: every driver's `advance` goes straight
        # on from such a wait, so only the resumes are saved (a dozen a tick in process).
        # 0 here: whoever drives `lockstep()` itself sees every wait (learn/match.py gates a
        # learner's loop on them); `loop` sets it, up to a scenario's `kill` tick, for `until`.
        self.skip_below = 0

    # ----------------------------------------------------------------- wiring
    def out(self, name: str, team: str = "", n: int | None = None, viewers_only: bool = False) -> Outbound[Any]:
        """An outbound key. `viewers_only`: nobody in the lockstep waits for it, so it
        is not put on the wire while nobody listens (it still counts in the digest).
        A key of `SERVED` (schemas/keys.py) is also served: a query gets its last frame."""
        key = self.keys.key(name, team, n)
        put = self.transport.publisher(key, when_matched=viewers_only, sign=self.keyring.signer(key))
        if self.tap is None:
            ob: Outbound[Any] = Outbound(key, self.keys.rel(key), put, self.digest)
        else:
            ob = TappedOutbound(key, self.keys.rel(key), put, self.digest, self.tap)
        if self.cooperative and not self.cfg.timing.batch:
            # No wire in a cooperative match: a batch's encode, decode and scan buy nothing there, and a
            # batch is a transport detail (the same digests). An explicit `timing.batch` still batches.
            ob.unbatched()
        if name in SERVED:
            latest = Latest()
            ob.put_through(latest.wrap)
            self.transport.serve(key, latest.get, sign=self.keyring.signer(key))
        self.outbound.append(ob)
        return ob

    def inp(
        self,
        name: str,
        team: str = "",
        n: int | None = None,
        *,
        check: Callable[[M], str | None] | None = None,
        ideal: bool = False,
        lag: int | None = None,
    ) -> Inbound[Any]:
        """An inbound key, with the schedule, lag and sender of its `KeySpec` (schemas/keys.py)
        and the periods of this match's configuration.

        `ideal`: no link emulation (a listener outside the modelled links), which may
        also take the frames with a shorter `lag` than the key's.
        """
        spec = KEY_BY_NAME[name]
        schedule = self.schedule(name)
        lag = spec.timing.lag if lag is None else lag
        sender = spec.sender_id(team, n)
        key = self.keys.key(name, team, n)
        model = IDEAL if ideal else self.links.get(spec.link_class, IDEAL)
        changes = () if ideal or not self.cfg.scenario.steps else scheduled(self.cfg, spec.link_class)
        emulator = LinkEmulator(model, seeds.rng(self.cfg.seed, "link", self.keys.rel(key), self.name), changes)
        verify, on_forged = self.mac_check(key, sender)
        ib: Inbound[Any] = Inbound(
            key=key,
            msg_type=spec.message,
            channel=None,
            schedule=schedule,
            lag=lag,
            link_class=spec.link_class,
            sender=sender,
            emulator=emulator,
            dt=self.cfg.timing.dt,
            rejections=self.rejections,
            watchdog=self.driver.watchdog,
            is_dead=self._is_gone,
            on_dead=self._record_dead,
            check=check,
        )
        ib.strict = not self.cfg.realtime
        self.driver.connect(ib, self.transport, verify, on_forged)
        self.inbound.append(ib)
        return ib

    def schedule(self, name: str) -> Schedule:
        """The schedule of key `name` in this match: its `Timing` with the configured periods."""
        return Schedule(*KEY_BY_NAME[name].timing.schedule(self.cfg.timing.periods()))

    # ------------------------------------------------------------------- loop
    def loop(self) -> Waits:
        """The whole match: the lockstep loop under the driver, or the real-time one with `--realtime`.
        Not a generator itself: it returns the driver's (a cooperative driver's is the lockstep loop
        itself), so that `playing` resumes it with one level of `yield from` less."""
        if self.cfg.realtime and not self.cooperative:
            self.loop_realtime()
            return iter(())
        stop = killed_at(self.cfg, self.name)
        self.skip_below = stop if stop >= 0 else 1 << 62  # see `Node.skip_below`
        steps = self.lockstep()
        if stop >= 0:  # a scenario's `kill` step: the loop ends before acting at that tick
            steps = until(steps, stop)
        return self.driver.drive(steps, self.batch_flusher())

    def lockstep(self) -> Waits:
        """The lockstep loop: yields (inbound, k) wherever it needs that link's frames due at k."""
        raise NotImplementedError

    def loop_realtime(self) -> None:
        raise NotImplementedError

    def batch_flusher(self) -> Callable[[], None] | None:
        """What a driver calls before this node waits on a link not `paired`: put its
        held-back batches (`Outbound.batch`); None if it batches nothing."""
        batched = tuple(o for o in self.outbound if o.batching)
        if not batched:
            return None

        def flush() -> None:
            for o in batched:
                o.flush()

        return flush

    def close(self) -> None:
        self.driver.close()

    def cpu_s(self) -> list[float]:
        return self.driver.cpu_s()


class Observer(Peer):
    """A process that watches a match from outside its lockstep (the recorder, the viewer):
    nobody waits for it, and it waits for nobody's frames in lockstep."""

    def loop(self) -> Waits:
        self.observe()
        yield from ()

    def observe(self) -> None:
        """Watch the match until it is over (or this process is stopped)."""
        raise NotImplementedError


def killed_at(cfg: MatchConfig, name: str) -> int:
    """The tick of a scenario's `KillProcess` step for process `name`, or -1."""
    if not cfg.scenario.steps:
        return -1
    from arena.schemas.messages import KillProcess

    ticks = [s.at for s in cfg.scenario.steps for a in s.actions if isinstance(a, KillProcess) and a.process == name]
    return min(ticks) if ticks else -1


def until(steps: Waits, stop: int) -> Waits:
    """`steps` up to the first wait at tick `stop` or later: the loop ends there, as a process that died."""
    for wait in steps:
        if wait[1] >= stop:
            steps.close()
            return
        yield wait
