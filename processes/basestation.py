"""Base station process: the team's fused world model, strategy and roles.

Inputs: every robot's `report` (Wi-Fi) and the `referee` frames (wired; a
frame that does not decode, or whose set piece has no team, is rejected). At
every tick of the `order` schedule it runs the strategy's team brain and sends
one `order` per robot over Wi-Fi. Schedules and lags are the keys'
(`KeySpec.timing`, schemas/README.md).
"""

from __future__ import annotations

from time import perf_counter

from arena.rules.referee_box import check_referee
from arena.runtime.lockstep import Waits
from arena.runtime.node import Node
from arena.strategies import registry
from arena.strategies.base import TeamContext


class BaseStationNode(Node):
    # slots: see `Peer` (runtime/node.py)
    __slots__ = "order_schedule report_in ref_in order_out brain via latest".split()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        cfg = self.cfg
        team = self.pid.team
        self.order_schedule = self.schedule("order")
        self.report_in = {n: self.inp("report", team, n) for n in range(cfg.robots)}
        self.ref_in = self.inp("referee", check=check_referee)
        self.order_out = {n: self.out("order", team, n) for n in range(cfg.robots)}
        strategy = registry.get(cfg.strategy_of(team))
        self.brain = strategy.make_team(TeamContext(cfg=cfg, team=team, rng=self.rng("strategy")))
        # --via-refbox (real time only): commands and score come over TCP from the RefBox bridge, as
        # a real team's would; the zenoh referee frames are then only the clock (docs/refbox.md).
        self.via = None
        if cfg.refbox.via:  # its TCP client imports socket: only for a match that plays via the RefBox
            from arena.refbox.follow import ViaRefbox

            self.via = ViaRefbox(cfg, team, self.log)
        self.latest: dict = {}

    def on_peer_dead(self, peer: str) -> None:
        """One of our robots is dead: it gets no more orders (`Outbound.mute`)."""
        kind, _, rest = peer.partition("/")
        team, _, n = rest.partition("/")
        if kind == "robot" and team == self.pid.team and n.isdigit() and int(n) in self.order_out:
            self.order_out[int(n)].mute()

    def act(self, k: int) -> None:
        t0 = perf_counter()
        # Each robot's newest report, if a new one arrived since the last order (a plain loop: no comprehension frame).
        reports: dict = {}
        for n, ib in self.report_in.items():
            if ib.take(k):
                reports[n] = ib.latest
        referee = self.ref_in.latest_by(k)
        if self.via is not None:
            referee = self.via.referee(k, reports)
            self.latest.update(reports)
            self.via.send_worldstate(k, self.latest)
        orders = self.brain.step(k, reports, referee)
        for n, out in self.order_out.items():
            out.send(orders[n])
        self.last_tick = k
        self._work_s.append(perf_counter() - t0)  # `timed(t0)`, one call less an order

    def lockstep(self) -> Waits:
        reports, ref_in, skip_below = list(self.report_in.values()), self.ref_in, self.skip_below
        for k in self.order_schedule.ticks(self.cfg.total_ticks):
            for ib in reports:
                ib.waited = k  # a wait not yielded (`Node.skip_below`)
                if k >= skip_below or k >= ib.ready_below:  # `not ib.ready(k)`, one call less
                    yield ib, k
            ref_in.waited = k
            if k >= skip_below or k >= ref_in.ready_below:
                yield ref_in, k
            self.act(k)

    def loop_realtime(self) -> None:
        try:
            self._loop_realtime()
        finally:
            if self.via is not None:
                self.via.close()

    def _loop_realtime(self) -> None:
        last = self.cfg.total_ticks
        while True:
            r = self.ref_in.recv_clock()
            if r is None:
                return
            k = self.order_schedule.first_after(r)
            if k > last:
                return
            for ib in self.report_in.values():
                ib.poll(k)
            self.act(k)
