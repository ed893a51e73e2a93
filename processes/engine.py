"""Game rule engine process: the pymunk world, the tick clock, ball events.

Per tick k (lockstep):

1. apply the referee frames delivered by k (`apply_command`): the side
   switch; STOP and every set-piece command stop play, and a set piece puts
   the ball on its spot and pins it there (KICKOFF also places every robot);
   START first moves every robot that is still too close to the ball spot to
   the nearest legal place (`setpieces.py`, docs/rules.md), then frees the
   ball; then a scenario's teleports due at k (sim/director.py);
2. publish every robot's `sense` for tick k, `world` (G_V), and every referee
   period the ball `events` (G_Re) gathered since the previous frame, with
   ROBOT_STUCK for robots driven but in one place (`StuckWatch`);
3. step the physics from k to k+1 with the commands delivered by k, i.e. the
   robots' `cmd` of tick k-1: while the engine steps, the robots already think
   about tick k (a one-tick actuation delay, as on a real robot).

In real-time mode the engine paces ticks to the wall clock and never waits for
a command: a robot without a fresh command keeps its last setpoint until
`cmd_timeout`, then stops.

A robot whose process died (liveliness lost, or silent past the watchdog) is
parked: taken off the field beyond the fence for the rest of the match, with no
collisions, and the referee gets a ROBOT_DEAD event (docs/architecture.md,
"Faults").

A RED_CARD, DOUBLE_YELLOW or REPAIR_OUT parks its robot the same way, but its
process plays on (rules/setpieces.py `Restarts.sent_off`); PENALTY places the robots for it.

Inputs are validated on the way in: a `cmd` with non-finite numbers or the
wrong number of wheel speeds for the robot model, and a `referee` frame with
an unknown command or team (`check_referee`), are rejected, counted and
logged, and the match goes on.
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from arena.config import TEAMS
from arena.rules.referee_box import check_referee
from arena.rules.setpieces import Restarts
from arena.runtime import seeds
from arena.runtime.drivers import Reactor
from arena.runtime.lockstep import Waits
from arena.runtime.node import Node, killed_at
from arena.runtime.pace import LIVE_WORLD_HZ, Pacer, WireGate
from arena.schemas.messages import BallEvent, Cmd, EngineEvents, FieldSpec, Referee, TeleportBall, TeleportRobot, encode
from arena.sim.director import Director, operator_inbox, referee_steps
from arena.sim.drive import Drive
from arena.sim.physics import Physics, StuckWatch
from arena.sim.sensors import NormalStream, sense_every


def check_cmd(cmd: Cmd, wheels: int) -> str | None:
    """Reject commands no robot could mean: non-finite numbers, a wheel count the model has not.
    (`EngineNode.check_cmd` passes the usual command itself, six times a tick, before calling this.)"""
    for name in ("vx", "vy", "omega", "kick_speed"):
        if not math.isfinite(getattr(cmd, name)):
            return f"{name} is not finite"
    if cmd.mode == "wheels" and len(cmd.wheels) != wheels:
        return f"{len(cmd.wheels)} wheel speeds (this robot has {wheels})"
    if not all(math.isfinite(w) for w in cmd.wheels):
        return "a wheel speed is not finite"
    return None


class EngineNode(Node):
    # slots: see `Peer` (runtime/node.py)
    __slots__ = (
        "robots physics restarts director operator wheels sensor_rng cmd_in ref_in sense_out sense_plan "
        "world_out events_out field_out events_schedule world_schedule pending_events stuck parked world_gate "
        "pacer"
    ).split()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        cfg = self.cfg
        self.robots = [(team, n) for team in TEAMS for n in range(cfg.robots)]
        self.physics = Physics(cfg)
        self.physics.attack_dir_a = cfg.scenario.attack_dir_a
        self.physics.kickoff_positions("a")
        self.physics.stop_play()
        self.restarts = Restarts(cfg, self.physics)
        # A scenario's steps (sim/director.py); its teleports at tick 0 are its start.
        self.director = Director(cfg, self.physics, self.refuse_step) if cfg.scenario.active else None
        self.operator = operator_inbox(self, (TeleportBall, TeleportRobot))  # live sessions: `arena operator`
        if any(t == 0 and o.command == "START" for t, o in referee_steps(cfg.scenario.steps)):
            self.physics.start_play()  # the ball is in play from tick 0, before the referee's frame arrives
        self.wheels = Drive(cfg.robot).wheels  # wheel speeds a `cmd` in mode "wheels" must carry
        self.sensor_rng = {
            r: NormalStream(np.random.default_rng(seeds.derive(cfg.seed, self.name, "sensor", *r))) for r in self.robots
        }
        self.cmd_in = {(team, n): self.inp("cmd", team, n, check=self.check_cmd) for team, n in self.robots}
        self.ref_in = self.inp("referee", check=check_referee)
        self.sense_out = {(team, n): self.out("sense", team, n) for team, n in self.robots}
        self.sense_plan = [(r, self.sensor_rng[r]) for r in self.sense_out]
        for ob in self.sense_out.values():  # L ticks of senses per message (config/__init__.py `frames_per_message`)
            ob.batch(cfg.timing.frames_per_message(cfg.realtime), cfg.total_ticks)
        for ib in self.cmd_in.values():
            ib.paired = True  # the robots batch their cmds on the same grid (runtime/lockstep.py `Outbound`)
        self.world_out = self.out("world", viewers_only=True)
        self.events_out = self.out("events")
        self.field_out = self.out("field")
        self.events_schedule = self.schedule("events")
        self.world_schedule = self.schedule("world")
        self.pending_events: list = []
        self.stuck = StuckWatch(cfg)  # driven robots that stay in one place (ROBOT_STUCK)
        self.parked: dict[tuple[str, int], dict[str, float]] = {}  # dead robots taken off the field
        self.world_gate: WireGate | None = None
        self.pacer = self._live_pacer()
        # Both answers carry the engine's MAC (runtime/mac.py): a process started by hand takes its
        # configuration from the reply that checks out (match/run.py `fetch_config`).
        config, field = self.keys.config(), self.keys.key("field")
        self.transport.serve(config, cfg.to_json().encode(), sign=self.keyring.signer(config))
        # `field` is put once, at tick 0; a late joiner (a viewer, a spectator) gets it with a `get`.
        self.transport.serve(field, encode(self.field_spec()), sign=self.keyring.signer(field))

    def _live_pacer(self) -> Pacer | None:
        """A live lockstep match (`--live`): the viewer's pace, pause and steps (runtime/pace.py)."""
        if self.cfg.live < 0 or self.cfg.realtime:
            return None
        pacer = Pacer(self.cfg.timing.dt, self.cfg.pace, self.log, self.cfg.timing.wait_timeout, self.clock)
        key = self.keys.control()
        # Unpaced, the viewer draws at most 30 frames a second of wall time: only every
        # Nth world frame goes on the wire, and the held one whenever the pacer holds
        # the match. Every frame is still digested (and recorded: the tap is in `send`).
        every = round(1.0 / (LIVE_WORLD_HZ * self.cfg.timing.dt * self.world_schedule.period))
        self.world_gate = WireGate(every)
        self.world_out.put_through(self.world_gate.wrap)
        pacer.on_hold = self.world_gate.flush

        def on_control(raw: bytes) -> None:
            problem = pacer.control_raw(raw)
            if problem:
                self.rejections.reject(key, *problem)

        # Only the viewer's frames, by their MAC (runtime/mac.py); the others are counted as forged.
        verify, on_forged = self.mac_check(key, "viewer")
        if isinstance(self.driver, Reactor):
            self.transport.subscribe_callback(key, on_control, verify, on_forged)
            pacer.start(self.driver.poke)
        else:
            channel = self.transport.subscribe(key, verify=verify, on_forged=on_forged)
            pacer.pull_from(channel.try_recv, on_control)
        return pacer

    def refuse_step(self, why: str) -> None:
        """A scenario step's teleport out of range (sim/director.py `check_action`): not applied, counted."""
        self.rejections.reject("scenario", "invalid", why)

    def check_cmd(self, cmd: Cmd) -> str | None:
        # `check_cmd`'s usual case inlined: the Inbound asks for each robot's command, six times a tick
        isfinite = math.isfinite
        if (
            cmd.mode == "body"
            and not cmd.wheels
            and isfinite(cmd.vx)
            and isfinite(cmd.vy)
            and isfinite(cmd.omega)
            and isfinite(cmd.kick_speed)
        ):
            return None
        return check_cmd(cmd, self.wheels)

    def park(self, r: tuple[str, int], k: int) -> None:
        """A dead robot leaves the field: parked beyond the fence, no collisions (Physics.park_robot)."""
        x, y = self.physics.park_robot(*r)
        self.sense_out[r].mute()  # nobody reads it any more
        self.parked[r] = {"tick": k, "x": round(x, 3), "y": round(y, 3)}
        level = logging.INFO if killed_at(self.cfg, f"robot/{r[0]}/{r[1]}") >= 0 else logging.WARNING  # `kill` step
        self.log.log(level, "tick %d: robot %s/%d is dead, parked at (%.2f, %.2f)", k, r[0], r[1], x, y)

    def on_peer_dead(self, peer: str) -> None:
        """Tell the referee (G_Re) that a robot is gone; its wheels are stopped in the loop."""
        pid = peer.split("/")
        if pid[0] == "robot" and len(pid) == 3:
            self.pending_events.append(
                BallEvent(kind="ROBOT_DEAD", tick=self.physics.tick, team=pid[1], robot=int(pid[2]))
            )

    # -------------------------------------------------------------- per tick
    def apply_referee(self, frames: list[Referee], k: int) -> None:
        for frame in frames:
            n = len(self.restarts.placed)
            self.restarts.apply_frame(frame)
            if self.director is not None:
                self.director.observe(frame)
            for tick, team, robot, x, y in self.restarts.placed[n:]:
                self.log.info(
                    "tick %d: robot %s/%d too close to the ball at START, placed at (%.2f, %.2f)",
                    tick,
                    team,
                    robot,
                    x,
                    y,
                )
        if self.director is not None:
            self.director.act(k)
        if self.operator is not None:
            for action in self.operator.take(k):
                if self.director is None:
                    self.director = Director(self.cfg, self.physics, self.refuse_step)
                self.director.apply(action)

    def publish(self, k: int) -> None:
        ph, sp = self.physics, self.cfg.sensor
        for out, z in zip(self.sense_out.values(), sense_every(ph, k, self.sense_plan, sp)):
            out.send(z)
        ws, es = self.world_schedule, self.events_schedule
        if k >= ws.phase and (k - ws.phase) % ws.period == 0:  # world_schedule.due(k), inlined
            self.world_out.send(ph.world(k))
        if k >= es.phase and (k - es.phase) % es.period == 0:
            self.pending_events.extend(self.stuck.check(ph))
            self.events_out.send(EngineEvents(tick=k, events=self.pending_events))
            self.pending_events = []

    def field_spec(self) -> FieldSpec:
        f, cfg = self.cfg.field, self.cfg
        return FieldSpec(
            tick=0,
            length=f.length,
            width=f.width,
            runoff=f.runoff,
            goal_width=f.goal_width,
            goal_height=f.goal_height,
            goal_depth=f.goal_depth,
            center_circle_radius=f.center_circle_radius,
            penalty_area_depth=f.penalty_area_depth,
            penalty_area_width=f.penalty_area_width,
            goal_area_depth=f.goal_area_depth,
            goal_area_width=f.goal_area_width,
            penalty_mark_distance=f.penalty_mark_distance,
            robots_per_team=cfg.robots,
            dt=cfg.timing.dt,
            total_ticks=cfg.total_ticks,
        )

    def loop(self) -> Waits:
        if self.pacer is not None:
            # A live match: the viewer's state now (a pause set before the start holds tick 0).
            key = self.keys.control()
            verify, on_forged = self.mac_check(key, "viewer")
            raw = self.transport.query(key, timeout=2.0, verify=verify, on_forged=on_forged)
            if raw is not None and (problem := self.pacer.control_raw(raw)):
                self.rejections.reject(key, problem[0], f"the viewer's control state: {problem[1]}")
        yield from super().loop()

    def lockstep(self) -> Waits:
        # The field frame is part of the loop, not of `loop()`: whoever drives the
        # generator (runtime/drivers.py: Reactor, Pull, the cooperative driver)
        # sends it first, so the engine's digest is the same under every driver.
        self.field_out.send(self.field_spec())
        last = self.cfg.total_ticks
        ph = self.physics
        pacer, ref_in, skip_below = self.pacer, self.ref_in, self.skip_below
        for k in range(last + 1):
            if pacer is not None:
                yield pacer, k  # type: ignore[misc] - duck-types an Inbound: it only ever waits
            skip = k < skip_below
            ref_in.waited = k  # a wait not yielded (`Node.skip_below`)
            if not (skip and k < ref_in.ready_below):  # `ref_in.ready(k)`, one call less
                yield ref_in, k
            t0 = time.perf_counter()
            frames = ref_in.take(k)
            if frames or self.director is not None or self.operator is not None:
                self.apply_referee(frames, k)  # not called for nothing (most ticks: no referee frame)
            self.publish(k)
            self.last_tick = k
            if k == last:
                if self.world_gate is not None:
                    self.world_gate.flush()
                self.timed(t0)
                break
            work = time.perf_counter() - t0
            for r, ib in self.cmd_in.items():
                ib.waited = k  # a wait not yielded (`Node.skip_below`)
                if not (skip and k < ib.ready_below):  # `ib.ready(k)`, one call less
                    yield ib, k
                frames = ib.take(k)
                if frames:
                    ph.command(r, frames[-1])
                elif ib.dead and r not in self.parked:
                    self.park(r, k)
            if self.director is not None:
                self.director.drive(k)  # a scenario's ControlRobot: its command, not the robot's
            t1 = time.perf_counter()
            self.pending_events.extend(ph.step())
            self._work_s.append(work + time.perf_counter() - t1)

    def loop_realtime(self) -> None:
        last = self.cfg.total_ticks
        dt = self.cfg.timing.dt
        timeout_ticks = max(1, int(round(self.cfg.robot.cmd_timeout / dt)))
        last_cmd = {r: 0 for r in self.robots}
        ph = self.physics
        self.field_out.send(self.field_spec())
        clock = self.clock  # the wall clock it keeps pace with (runtime/clock.py)
        start = clock.monotonic()
        for k in range(last + 1):
            t0 = time.perf_counter()
            self.ref_in.poll(k)
            self.apply_referee(self.ref_in.take(k), k)
            self.publish(k)
            self.last_tick = k
            if k == last:
                break
            for r, ib in self.cmd_in.items():
                ib.poll(k)
                frames = ib.take(k)
                if frames:
                    ph.set_command(r[0], r[1], frames[-1])
                    last_cmd[r] = k
                elif k - last_cmd[r] > timeout_ticks:
                    ph.set_command(r[0], r[1], Cmd(tick=k))
                    peer = f"robot/{r[0]}/{r[1]}"
                    if peer in self.gone and r not in self.parked:  # its liveliness token vanished
                        self._record_dead(peer, "its liveliness token vanished")
                        self.park(r, k)
            if self.director is not None:
                self.director.drive(k)
            self.pending_events.extend(ph.step())
            self.timed(t0)
            self.announce_spoofing()  # (no Reactor in real time to say it ten times a second)
            delay = start + (k + 1) * dt - clock.monotonic()
            if delay > 0:
                clock.sleep(delay)

    def close(self) -> None:
        super().close()
        if self.pacer is not None:
            self.pacer.stop()

    def summary_extra(self) -> dict[str, object]:
        return (
            {
                "distance_m": {f"{t}/{n}": round(d, 3) for (t, n), d in sorted(self.physics.distance.items())},
                "ticks": self.last_tick,
                "placed": len(self.restarts.placed),
                "parked": {f"{t}/{n}": p for (t, n), p in sorted(self.parked.items())},
                "sent_off": [{"tick": k, "robot": f"{t}/{n}", "command": c} for k, t, n, c in self.restarts.sent_off],
            }
            | (self.operator.summary() if self.operator is not None else {})
            | self.director_extra()
        )

    def director_extra(self) -> dict[str, object]:
        """Teleports a scenario or the operator asked for that went to another spot (safely, or onto a robot)."""
        return {"teleports_moved": self.director.moved} if self.director is not None and self.director.moved else {}
