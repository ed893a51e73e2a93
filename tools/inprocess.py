"""A whole match in one Python process over the in-memory transport.

Every process kind runs in its own thread with the very same `Node` code as
in a real match, but the transport is `MemoryTransport`. This is for fast unit
and determinism tests of process logic; it is never what `arena match` runs.
"""

from __future__ import annotations

import threading

from arena.processes import node_class
from arena.runtime.config import MatchConfig
from arena.runtime.transport import MemoryBus, MemoryTransport
from arena.schemas.keys import Keys
from arena.schemas.messages import Summary


def play_in_process(cfg: MatchConfig, watch: tuple[str, ...] = ("world",), timeout: float = 120.0):
    """Play `cfg` in threads. Returns (summaries by process, {key name: [payload, ...]})."""
    bus = MemoryBus()
    keys = Keys("inprocess")
    taps = {name: bus.subscribe(None, keys.key(name)) for name in watch}
    summaries: dict[str, Summary] = {}
    errors: list[BaseException] = []

    def run(pid) -> None:
        try:
            node = node_class(pid.kind)(pid, cfg, MemoryTransport(bus), keys)
            summaries[str(pid)] = node.run()
        except BaseException as exc:  # reported to the caller below
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(p,), name=str(p), daemon=True) for p in cfg.processes()]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout)
        if t.is_alive():
            raise TimeoutError(f"{t.name} did not finish within {timeout:g} s")
    if errors:
        raise errors[0]
    frames = {}
    for name, ch in taps.items():
        got = []
        while (raw := ch.try_recv()) is not None:
            got.append(raw)
        frames[name] = got
    return summaries, frames
