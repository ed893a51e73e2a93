"""Referee process: runs the RefereeBox (referee_box.py) on the engine's ball events (G_Re).

Input: `engine/events`. Output: `referee`, on their schedules (`KeySpec.timing`,
schemas/README.md): a snapshot of the box's state plus the commands issued since
the previous frame (Re_G for the engine, and for both base stations). A
scenario's referee overrides are forced at the first referee tick at or after
their own (`RefereeBox.step`, `Forced`).
"""

from __future__ import annotations

import time

from arena.rules.referee_box import RefereeBox
from arena.runtime.lockstep import Waits
from arena.runtime.node import Node
from arena.schemas.messages import RefereeOverride
from arena.sim.director import check_action, operator_inbox, referee_steps


class RefereeNode(Node):
    # slots: see `Peer` (runtime/node.py)
    __slots__ = "ref_schedule events_in ref_out box follower decide forced operator".split()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.ref_schedule = self.schedule("referee")
        self.events_in = self.inp("events")
        self.ref_out = self.out("referee")
        self.box = RefereeBox(self.cfg)
        # --refbox-follow: a human at a real MSL RefBox decides (docs/refbox.md); our rules only end the match.
        self.follower = None
        if self.cfg.refbox.follow:  # its TCP client imports socket: only for a match that follows one
            from arena.refbox.follow import Follower

            self.follower = Follower(self.box, self.log)
        self.decide = self.follower.step if self.follower else self.box.step
        # A scenario's referee overrides (sim/director.py), each forced at the first referee tick >= its own.
        self.forced = []
        for at, o in referee_steps(self.cfg.scenario.steps):
            why = check_action(self.cfg, o)
            if why is None:
                self.forced.append((at, o))
            else:  # not forced, counted: the match goes on
                self.rejections.reject("scenario", "invalid", f"step at tick {at}: {why}")
        self.operator = operator_inbox(self, (RefereeOverride,))  # live sessions: `arena operator`

    def act(self, k: int) -> None:
        t0 = time.perf_counter()
        events = []  # a plain loop: usually one frame, often with no event
        for frame in self.events_in.take(k):
            events += frame.events
        due: tuple = ()
        if self.forced and self.forced[0][0] <= k:
            due = tuple(o for at, o in self.forced if at <= k)
            self.forced = [(at, o) for at, o in self.forced if at > k]
        live = tuple(self.operator.take(k)) if self.operator is not None else ()
        if due or live:
            self.ref_out.send(self.box.frame(k, self.box.step(k, events, due, live)))
        else:
            self.ref_out.send(self.box.frame(k, self.decide(k, events)))
        self.last_tick = k
        self.timed(t0)

    def lockstep(self) -> Waits:
        for k in self.ref_schedule.ticks(self.cfg.total_ticks):
            yield self.events_in, k
            self.act(k)

    def loop_realtime(self) -> None:
        last = self.cfg.total_ticks
        self.act(0)
        while True:
            e = self.events_in.recv_clock()
            if e is None:
                return
            k = self.ref_schedule.first_after(e)
            self.act(min(k, last))
            self.announce_spoofing()  # (no Reactor in real time to say it ten times a second)
            if k >= last:
                return

    def summary_extra(self) -> dict[str, object]:
        out = self.box.summary()
        if self.operator is not None:
            out.update(self.operator.summary())
        if self.follower is not None:
            out["refbox_follow"] = self.follower.summary()
        return out
