"""RefBox bridge process: our referee's commands to real base stations over TCP, in the MSL RefBox protocol.

Inputs: the `referee` frames (no link emulation: the TCP connection is the
real link). Outputs: `refbox/<team>/worldstate`, every valid worldstate a
team's base station sent, for the recorder (docs/refbox.md).

The bridge is a listener only. Nobody in the match waits for it after the
start, and nothing it sends is an input of another process, so it cannot
change a lockstep digest; `arena match` leaves its digest out of the match
digest, as the recorder's (its content depends on what the teams send). The
TCP server (refbox/server.py) runs on its own thread: a slow or silent
base station never holds up the referee frames, and the match never waits for
a TCP client, unless `--refbox-wait N` holds the start until N base stations
are connected.
"""

from __future__ import annotations

import time

from arena.config import TEAMS
from arena.refbox.server import BridgeServer
from arena.rules import refbox_protocol as rp
from arena.rules.referee_box import check_referee
from arena.runtime.lockstep import Waits
from arena.runtime.node import Node, StartupError
from arena.schemas.messages import Worldstate


class RefboxNode(Node):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        cfg = self.cfg
        self.ref_schedule = self.schedule("referee")
        # Lag 0 and no emulation: forward each frame at its own tick, END_GAME included.
        self.ref_in = self.inp("referee", check=check_referee, ideal=True, lag=0)
        self.ws_out = {t: self.out("worldstate", t) for t in TEAMS}
        host, port = rp.parse_endpoint(cfg.refbox.listen)
        # Listening before the start barrier: a base station can connect while the match starts.
        self.server = BridgeServer(host, port, cfg.refbox, self.log)
        self.log.warning("refbox: listening on tcp/%s:%d", host, self.server.port)
        self.forwarded = 0
        self._clock = (0, self.clock.monotonic())  # real time: (tick, wall time) of the last referee frame
        self._ws_tick = 0  # worldstate ticks never go back (the recorder writes in tick order)

    def barrier(self) -> None:
        # Our own base stations (--via-refbox) must hear the first FIRST_HALF and KICKOFF too.
        want = 2 if self.cfg.refbox.via else self.cfg.refbox.wait
        deadline = self.clock.monotonic() + self.cfg.timing.startup_timeout
        while self.server.sides() < want:
            if self.clock.monotonic() > deadline:
                raise StartupError(
                    f"refbox: {self.server.sides()} of {want} base stations connected within "
                    f"{self.cfg.timing.startup_timeout:g} s (--refbox-wait)"
                )
            self.clock.wait(self.server.connected, 0.2)
            self.server.connected.clear()
        super().barrier()

    def act(self, k: int) -> None:
        t0 = time.perf_counter()
        for frame in self.ref_in.take(k):
            for c in frame.commands:
                self.server.broadcast(rp.OUR_TO_WIRE.get(c.name, c.name), c.team, c.robot)
                self.forwarded += 1
        self._worldstates(k)
        if self.tap is not None:
            self.tap.advance(k)
        self.last_tick = k
        self.timed(t0)

    def _worldstates(self, k: int) -> None:
        for team, address, r, at in self.server.drain():
            if r.doc is None:
                self.rejections.reject(self.ws_out[team].key, f"worldstate-{r.reason}", r.detail)
                continue
            self._ws_tick = max(self._ws_tick, self.tick_at(at, k))
            msg = Worldstate(tick=self._ws_tick, team=team, address=address, age_ms=float(r.doc["ageMs"]), json=r.raw)
            self.ws_out[team].send(msg)

    def finish(self) -> None:
        """After the last command: close the connections, keep what the teams sent until then."""
        self.server.close()
        self._worldstates(self.last_tick)

    def tick_at(self, wall: float, k: int) -> int:
        """The match tick at wall time `wall`: in real time, counted on from the last
        referee frame (bridge bookkeeping only, never simulation); in lockstep,
        whose ticks have no wall time, the tick being forwarded."""
        if not self.cfg.realtime:
            return k
        tick, since = self._clock
        return max(0, min(k, tick + round((wall - since) / self.cfg.timing.dt)))

    def lockstep(self) -> Waits:
        for k in self.ref_schedule.ticks(self.cfg.total_ticks):
            yield self.ref_in, k
            self.act(k)
        self.finish()

    def loop_realtime(self) -> None:
        last = self.cfg.total_ticks
        try:
            while True:
                r = self.ref_in.recv_clock()
                if r is None:
                    return
                self._clock = (min(r, last), self.clock.monotonic())
                self.act(min(r, last))
                if r >= last:
                    return
        finally:
            self.finish()

    def summary_extra(self) -> dict[str, object]:
        s = self.server
        return {
            "port": s.port,
            "commands_forwarded": self.forwarded,
            "counts": dict(sorted(s.counts.items())),
            "worldstate_errors": {t: dict(sorted(c.items())) for t, c in s.errors.items()},
        }
