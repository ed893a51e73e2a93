"""Robot process: perception in, behaviour, command out (one per robot).

Inputs: `sense` from the engine (the robot acts at tick k on the sense of tick
k - L, L the configured perception latency, `timing.perception_latency`) and
its base station's `order` (Wi-Fi). Outputs: `cmd` (the engine applies it from
the next tick on, a one-tick actuation delay) and `report`. Schedules and lags
are the keys' (`KeySpec.timing`, schemas/README.md).
"""

from __future__ import annotations

from time import perf_counter

from arena.runtime.lockstep import Schedule, Waits
from arena.runtime.node import Node
from arena.strategies import registry
from arena.strategies.base import RobotContext


class RobotNode(Node):
    # slots: see `Peer` (runtime/node.py)
    __slots__ = "report_schedule sense_in order_in cmd_out report_out brain".split()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        cfg = self.cfg
        team, n = self.pid.team, self.pid.robot
        self.report_schedule = self.schedule("report")
        # The perception latency L: at tick k the robot sees the sense of tick k - L.
        self.sense_in = self.inp("sense", team, n, lag=cfg.timing.perception_latency)
        self.order_in = self.inp("order", team, n)
        self.cmd_out = self.out("cmd", team, n)
        self.cmd_out.batch(cfg.timing.frames_per_message(cfg.realtime), cfg.total_ticks)
        self.sense_in.paired = True  # the engine batches senses on the same grid (runtime/lockstep.py `Outbound`)
        self.report_out = self.out("report", team, n)
        strategy = registry.get(cfg.strategy_of(team))
        self.brain = strategy.make_robot(RobotContext(cfg=cfg, team=team, n=n, rng=self.rng("strategy")))

    def act(self, k: int) -> None:
        t0 = perf_counter()
        sense = self.sense_in.latest_by(k)
        order = self.order_in.latest_by(k)
        self.cmd_out.send(self.brain.step(k, sense, order))
        if self.report_schedule.due(k):
            self.report_out.send(self.brain.report(k, sense))
        self.last_tick = k
        self._work_s.append(perf_counter() - t0)  # `timed(t0)`, one call less a tick

    def lockstep(self) -> Waits:
        sense_in, order_in, skip_below = self.sense_in, self.order_in, self.skip_below
        latest_sense, latest_order, work = sense_in.latest_by, order_in.latest_by, self._work_s
        # `act` inlined below (one Python call less a robot and tick), the report schedule's `due` as one
        # comparison with the next report tick; a subclass's own `act` or another schedule (a test's) is called
        schedule = self.report_schedule
        inline = type(self).act is RobotNode.act and type(schedule) is Schedule
        report_at, period = (schedule.first_after(-1), schedule.period) if inline else (-1, 0)
        for k in range(self.cfg.total_ticks + 1):
            sense_in.waited = k  # a wait not yielded (`Node.skip_below`)
            if k >= skip_below or k >= sense_in.ready_below:  # `not sense_in.ready(k)`, one call less
                yield sense_in, k
            order_in.waited = k
            if k >= skip_below or k >= order_in.ready_below:
                yield order_in, k
            if not inline:
                self.act(k)
                continue
            t0 = perf_counter()
            sense = latest_sense(k)
            self.cmd_out.send(self.brain.step(k, sense, latest_order(k)))
            if k == report_at:
                self.report_out.send(self.brain.report(k, sense))
                report_at += period
            self.last_tick = k
            work.append(perf_counter() - t0)

    def loop_realtime(self) -> None:
        last = self.cfg.total_ticks
        while True:
            k = self.sense_in.recv_clock()
            if k is None:
                return
            self.order_in.poll(k)
            self.act(k)
            if k >= last:
                return
