"""Viewer process: watch a match as it plays, in the Foxglove app (docs/recording.md).

`arena match --live [PORT]` starts it; `arena run viewer` attaches one to a
match by hand. It serves the Foxglove WebSocket protocol (foxglove-sdk's
server, which runs on the SDK's own threads) with:

* `/scene` (`foxglove.SceneUpdate`, recording/scene.py): the field, robots by
  team with id and role, the ball with its height, score and clock, and
  faintly what the teams believe: each robot's perceived ball (its last
  `report`) and each base station's fused P_ball (its last `order` to robot
  0), asked for `BELIEF_HZ` times a second of wall time: their senders serve
  them (runtime/node.py), so a viewer costs a robot nothing per report, where
  a subscription cost it one more put per report, hundreds a second in an
  unpaced match. The field is
  part of every update, and the last update is sent again while the match
  stands still, so a viewer that connects late sees the field at once;
* `/referee_log` (`foxglove.Log`): every referee command and engine event;
* `/match` (JSON): tick, time, stage, command in force, score, pause state;
* parameters `paused`, `step` and `pace` (Foxglove's Parameters panel), which
  in a lockstep match pause the engine, step it tick by tick and set its pace
  (runtime/pace.py, through `Control` frames on `arena/<m>/control`);
* client messages on `/operator` (Foxglove's Publish panel, JSON
  `{"actions": [...]}`), put as `Operator` frames on `arena/<m>/operator` for
  the engine and the referee of a live session (docs/scenarios.md), signed
  with the operator's MAC. Only a viewer `arena match` starts for a local
  operator holds that key (no `--secure`, Foxglove served on a loopback
  address: whoever reaches the port is on the operator's own computer);
  any other viewer refuses these messages, counted, and says to use
  `arena operator` with the operator's credentials (in a secure match the
  router drops a viewer's puts there anyway: only the `operator` principal
  may put there).

It is in nobody's lockstep and has none of its own: it subscribes with rings
that keep the newest frames (a viewer that falls behind drops, never blocks),
`world` is published with congestion control DROP, it sends no data key (its
digest is empty and `arena match` leaves it out of the match digest), an
unpaced live match puts only every 5th `world` frame on the wire
(runtime/pace.py `WireGate`), and the viewer runs behind the match's
processes on the processor (`lower_priority`). So the same loop (`watch`) serves lockstep and
`--realtime` alike, and a match digests the same with and without it.
"""

from __future__ import annotations

import collections
import functools
import os
import threading
import time

import foxglove
import msgspec
from foxglove.messages import Log, SceneUpdate
from foxglove.websocket import Capability, Parameter, ServerListener

from arena.config import TEAMS, ConfigError
from arena.recording import scene
from arena.runtime.node import Observer
from arena.schemas.keys import OPERATOR_PRINCIPAL
from arena.schemas.messages import (
    Control,
    EngineEvents,
    FieldSpec,
    Operator,
    Order,
    Referee,
    RefereeOverride,
    Report,
    TeleportBall,
    TeleportRobot,
    World,
)

POLL_S = 0.02  # [s] wall: pause between polls of the subscriptions
SCENE_HZ = 30.0  # [Hz] wall: at most this many scene updates per second, whatever the match's speed
REPEAT_S = 0.5  # [s] wall: a match standing still (paused, starting) has its last scene sent again this often
LINGER_S = 0.25  # [s] wall: at the end, wait this long for the last frames, then for the clients
NICE = 10  # [-] niceness (Linux) of the viewer's threads and of its autogroup: the match's processes come first
RING = 4096  # [frames] referee and event frames kept between two polls (each carries commands)
MATCH_TOPIC = "/match"
MATCH_SCHEMA = {
    "type": "object",
    "properties": {
        k: {"type": t}
        for k, t in (
            ("tick", "integer"),
            ("t", "number"),
            ("stage", "string"),
            ("command", "string"),
            ("score_a", "integer"),
            ("score_b", "integer"),
            ("paused", "boolean"),
            ("pace", "number"),
        )
    },
}


BELIEF_HZ = 10.0  # [Hz] wall: how often the viewer asks each robot and base station what it believes
ASK_S = 1.0  # [s] wall: an answer later than this is not waited for


def lower_priority(idle: bool) -> list[str]:
    """Put every thread of this process behind the match's; returns what was done.

    Niceness is per thread on Linux, and zenoh's receive threads and the
    Foxglove server's exist before the loop starts, so each thread of
    /proc/self/task is reniced. With autogroups (a desktop kernel's default)
    a process in a session of its own, as `arena match` starts every process,
    competes as its own group and a thread's niceness counts only inside
    it: the group's niceness is set too, only when the session is the
    viewer's alone. `idle` (an unpaced lockstep match, which takes every
    cycle it can): SCHED_IDLE, so any match process that wakes takes the
    processor from the viewer at once. Anything refused is left as it was.
    """
    done = []
    if os.getsid(0) == os.getpid():
        try:
            with open("/proc/self/autogroup", "w") as f:
                f.write(str(NICE))
            done.append(f"autogroup nice {NICE}")
        except OSError:
            pass
    tids = os.listdir("/proc/self/task") if os.path.isdir("/proc/self/task") else [str(os.getpid())]
    policy = []
    for tid in map(int, tids):
        try:
            os.setpriority(os.PRIO_PROCESS, tid, max(NICE, os.getpriority(os.PRIO_PROCESS, tid)))
            if idle:
                os.sched_setscheduler(tid, os.SCHED_IDLE, os.sched_param(0))
            policy.append(tid)
        except (OSError, AttributeError):
            pass
    done.append(f"{len(policy)} of {len(tids)} threads at nice {NICE}" + (", SCHED_IDLE" if idle else ""))
    return done


class _Listener(ServerListener):
    """The SDK's callbacks (its own threads) for the viewer's parameters; the rest keep the defaults."""

    def __init__(self, node: ViewerNode):
        self.node = node

    def on_get_parameters(self, client, param_names, request_id=None):
        return self.node.on_get_parameters(client, param_names, request_id)

    def on_set_parameters(self, client, parameters, request_id=None):
        return self.node.on_set_parameters(client, parameters, request_id)

    def on_client_advertise(self, client, channel):
        self.node.client_topics[(client.id, channel.id)] = channel.topic

    def on_client_unadvertise(self, client, client_channel_id):
        self.node.client_topics.pop((client.id, client_channel_id), None)

    def on_message_data(self, client, client_channel_id, data):
        self.node.on_client_message(self.node.client_topics.get((client.id, client_channel_id), ""), data)


class OperatorRequest(msgspec.Struct, forbid_unknown_fields=True):
    """What the Foxglove Publish panel sends on `/operator` (JSON): the actions of an `Operator` frame."""

    actions: list[TeleportBall | TeleportRobot | RefereeOverride]


OPERATOR_TOPIC = "/operator"


class ViewerNode(Observer):
    def _owned(self, name: str, sender: str) -> dict:
        """Only the owner's frames (their MAC, runtime/mac.py), when this viewer holds the owner's key."""
        key = self.keys.key(name)
        verify = self.keyring.verifier(sender, key)
        return {"verify": verify, "on_forged": functools.partial(self.rejections.reject, key, "forged", sender)}

    def __init__(self, *args, host: str = "127.0.0.1", attached: bool = False, **kwargs):
        super().__init__(*args, **kwargs)
        cfg, keys, tr = self.cfg, self.keys, self.transport
        self.world_in = tr.subscribe(keys.key("world"), latest=1, **self._owned("world", "engine"))
        # drawn from the configuration; checked against it
        self.field_in = tr.subscribe(keys.key("field"), latest=1, **self._owned("field", "engine"))
        self.referee_in = tr.subscribe(keys.key("referee"), latest=RING, **self._owned("referee", "referee"))
        self.events_in = tr.subscribe(keys.key("events"), latest=RING, **self._owned("events", "engine"))
        # What the teams believe is asked for (their senders serve the last frame, runtime/node.py),
        # one key at a time: the access control of a secure match allows no wildcard.
        self.report_keys = {keys.key("report", t, n): t for t in TEAMS for n in range(cfg.robots)}
        self.order_keys = {keys.key("order", t, 0): t for t in TEAMS}
        senders = {keys.key("report", t, n): f"robot/{t}/{n}" for t in TEAMS for n in range(cfg.robots)}
        senders |= {key: f"basestation/{t}" for key, t in self.order_keys.items()}
        self._ask_owned = {  # only their senders' answers (their MAC)
            key: {
                "verify": self.keyring.verifier(sender, key),
                "on_forged": functools.partial(self.rejections.reject, key, "forged", sender),
            }
            for key, sender in senders.items()
        }
        self._answers: collections.deque[tuple[str, bytes]] = collections.deque(maxlen=RING)  # transport threads
        self.control_put = tr.publisher(keys.control(), sign=self.keyring.signer(keys.control()))
        # A live session's operator frames from the Foxglove Publish panel (docs/scenarios.md), signed
        # as the operator: only a viewer started for a local operator holds its key (module doc).
        self.operator_sign = self.keyring.signer(keys.operator(), sender=OPERATOR_PRINCIPAL)
        keyless = self.keyring.own is None  # started by hand without credentials: nobody verifies anything
        self.operator_put = (
            tr.publisher(keys.operator(), sign=self.operator_sign) if self.operator_sign or keyless else None
        )
        self.client_topics: dict[tuple[int, int], str] = {}
        self.operator_seq = 0
        # The engine asks for the viewer's state once before tick 0 (a pause set before
        # the start holds tick 0); every change after that is put on the same key.
        tr.serve(keys.control(), self._control_state, sign=self.keyring.signer(keys.control()))
        self._dec_world = msgspec.msgpack.Decoder(World).decode
        self._dec_field = msgspec.msgpack.Decoder(FieldSpec).decode
        self._dec_ref = msgspec.msgpack.Decoder(Referee).decode
        self._dec_events = msgspec.msgpack.Decoder(EngineEvents).decode
        self._dec_report = msgspec.msgpack.Decoder(Report).decode
        self._dec_order = msgspec.msgpack.Decoder(Order).decode
        self.builder = scene.SceneBuilder(cfg)
        self.seen: dict[tuple[str, int], tuple[float, float]] = {}
        self.fused: dict[str, tuple[float, float, float]] = {}
        self.world: World | None = None
        self.ref: Referee | None = None
        self.lockstep_control = not cfg.realtime and not attached  # the engine has a pacer
        self.paused = False
        self.pace = cfg.pace
        self._seq = 0
        self._control = Control(tick=0, seq=0, pace=self.pace)
        self._lock = threading.Lock()
        self.scenes = 0
        self.logs = 0
        self.ctx = ctx = foxglove.Context()  # kept: a dropped context closes its channels
        self.scene_ch = foxglove.Channel(
            scene.SCENE_TOPIC, context=ctx, message_encoding="protobuf", schema=SceneUpdate.get_schema()
        )
        self.log_ch = foxglove.Channel(
            scene.LOG_TOPIC, context=ctx, message_encoding="protobuf", schema=Log.get_schema()
        )
        self.match_ch = foxglove.Channel(MATCH_TOPIC, context=ctx, schema=MATCH_SCHEMA)
        caps = [Capability.Time, Capability.ClientPublish] + ([Capability.Parameters] if self.lockstep_control else [])
        try:
            self.server = foxglove.start_server(
                name=f"soccer-arena {keys.match}",
                host=host,
                port=max(0, cfg.live),
                context=ctx,
                capabilities=caps,
                server_listener=_Listener(self),
                supported_encodings=["json"],
                message_backlog_size=256,
            )
        except RuntimeError as exc:
            raise ConfigError(f"viewer: cannot serve on {host}:{max(0, cfg.live)}: {exc}") from None
        self.port = self.server.port
        self.log.warning("live viewer: ws://%s:%d (Foxglove: Open connection)", host, self.port)

    # ------------------------------------------------- Foxglove parameters
    def _parameters(self) -> list[Parameter]:
        return [
            Parameter("paused", value=self.paused),
            Parameter("step", value=0),
            Parameter("pace", value=float(self.pace)),
        ]

    def on_get_parameters(self, client, param_names, request_id=None):
        with self._lock:
            return [p for p in self._parameters() if not param_names or p.name in param_names]

    def on_set_parameters(self, client, parameters, request_id=None):
        """Runs on the SDK's thread: sends a `Control` frame to the engine at once."""
        if not self.lockstep_control:
            return self._parameters()
        with self._lock:
            step = 0
            for p in parameters:
                value = p.get_value()
                if p.name == "paused" and isinstance(value, bool):
                    self.paused = value
                elif p.name == "step" and isinstance(value, int | float) and 0 < value <= 1_000_000:
                    step, self.paused = int(value), True
                elif p.name == "pace" and isinstance(value, int | float) and 0 <= value <= 1000:
                    self.pace = float(value)
                else:
                    self.rejections.reject("parameter", "invalid", f"{p.name}={value!r}")
            self._seq += 1
            tick = self.world.tick if self.world is not None else 0
            self._control = Control(tick=tick, seq=self._seq, paused=self.paused, step=step, pace=self.pace)
            self.control_put(msgspec.msgpack.encode(self._control))  # a put from another thread is safe
            return self._parameters()

    def on_client_message(self, topic: str, data: bytes) -> None:
        """A Foxglove client published on `/operator`: forward its actions as an `Operator` frame."""
        if topic != OPERATOR_TOPIC:
            return
        try:
            req = msgspec.json.decode(data, type=OperatorRequest)
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            self.rejections.reject(self.keys.operator(), "malformed", f"from Foxglove: {exc}")
            return
        if self.operator_put is None:
            self.rejections.reject(
                self.keys.operator(),
                "refused",
                "from Foxglove: this viewer holds no operator key (started by arena match for a local "
                "operator only); use arena operator --credentials operator.json5",
            )
            return
        # As `arena operator` counts: microseconds, so either's next frame comes after the other's last.
        self.operator_seq = max(self.operator_seq + 1, time.time_ns() // 1000)
        self.operator_put(msgspec.msgpack.encode(Operator(seq=self.operator_seq, actions=req.actions)))

    def _control_state(self) -> bytes:
        with self._lock:
            return msgspec.msgpack.encode(self._control)

    # ----------------------------------------------------------------- work
    def _drain(self) -> bool:
        """Take what has arrived; True if the match moved on."""
        moved = False
        raw = last = None
        while (raw := self.world_in.try_recv()) is not None:
            last = raw
        if last is not None:
            self.world = self._dec_world(last)
            moved = True
        if (raw := self.field_in.try_recv()) is not None:
            try:
                spec = self._dec_field(raw)
                f = self.cfg.field
                if (spec.length, spec.width, spec.goal_width) != (f.length, f.width, f.goal_width):
                    self.rejections.reject(
                        self.keys.key("field"), "invalid", "the field frame differs from the configuration"
                    )
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self.rejections.reject(self.keys.key("field"), "malformed", str(exc)[:120])
        while (raw := self.referee_in.try_recv()) is not None:
            try:
                ref = self._dec_ref(raw)
            except (msgspec.DecodeError, msgspec.ValidationError) as exc:
                self.rejections.reject(self.keys.key("referee"), "malformed", str(exc)[:120])
                continue
            self.ref = ref
            for b in self.builder.referee_log(ref, self._ns(ref.tick)):
                self.log_ch.base.log(b, self._ns(ref.tick))
                self.logs += 1
        while (raw := self.events_in.try_recv()) is not None:
            try:
                ev = self._dec_events(raw)
            except (msgspec.DecodeError, msgspec.ValidationError):
                continue
            for b in self.builder.events_log(ev, self._ns(ev.tick)):
                self.log_ch.base.log(b, self._ns(ev.tick))
        while self._answers:
            self._belief(*self._answers.popleft())
        return moved

    def ask_beliefs(self) -> None:
        """Ask every robot for its last report and every base station for its order to robot 0."""
        for key in (*self.report_keys, *self.order_keys):
            self.transport.ask(key, functools.partial(self._answer, key), ASK_S, **self._ask_owned[key])

    def _answer(self, key: str, raw: bytes) -> None:
        """On the transport's thread: a deque's append is thread-safe, the loop takes them in turn."""
        self._answers.append((key, raw))

    def _belief(self, key: str, raw: bytes) -> None:
        try:
            if key in self.order_keys:
                o = self._dec_order(raw)
            else:
                r = self._dec_report(raw)
        except (msgspec.DecodeError, msgspec.ValidationError) as exc:
            self.rejections.reject(key, "malformed", str(exc)[:120])
            return
        if key in self.order_keys:
            team = self.order_keys[key]
            if o.ball_valid:
                self.fused[team] = (o.ball_x, o.ball_y, o.ball_z)
            else:
                self.fused.pop(team, None)
            return
        team = self.report_keys[key]
        self.builder.roles[(team, r.robot)] = r.role or self.builder.roles.get((team, r.robot), "")
        if r.ball.visible:
            self.seen[(team, r.robot)] = (r.ball.x, r.ball.y)
        else:
            self.seen.pop((team, r.robot), None)

    def _ns(self, tick: int) -> int:
        return round(tick * self.cfg.timing.dt * 1e9)

    def act(self) -> None:
        """One scene: what the match looks like now, to every subscribed client."""
        w = self.world
        if w is None:
            return
        ns = self._ns(w.tick)
        self.server.broadcast_time(ns)
        if self.scene_ch.base.has_sinks():
            extra = self.builder.beliefs(ns, self.seen, self.fused)
            self.scene_ch.base.log(self.builder.update(w, ns, extra), ns)
            self.scenes += 1
        ref = self.ref
        self.match_ch.log(
            {
                "tick": w.tick,
                "t": round(w.t, 3),
                "stage": ref.stage if ref else "PRE_GAME",
                "command": ref.command if ref else "STOP",
                "score_a": ref.score_a if ref else 0,
                "score_b": ref.score_b if ref else 0,
                "paused": self.paused,
                "pace": self.pace,
            },
            log_time=ns,
        )
        self.last_tick = w.tick

    def _over(self) -> bool:
        w = self.world
        return (w is not None and w.tick >= self.cfg.total_ticks) or "engine" in self.gone

    def watch(self) -> None:
        every = 1.0 / SCENE_HZ
        next_scene = last_scene = next_ask = 0.0
        while True:
            moved = self._drain()
            now = self.clock.monotonic()
            if now >= next_ask and self.world is not None:
                self.ask_beliefs()
                next_ask = now + 1.0 / BELIEF_HZ
            if (moved and now >= next_scene) or now - last_scene >= REPEAT_S:
                self.act()
                next_scene, last_scene = now + every, now
            if self._over():
                end = self.clock.monotonic() + LINGER_S  # the last frames may still be on their way
                while self.clock.monotonic() < end:
                    self.clock.sleep(POLL_S)
                    self._drain()
                self.act()
                self.clock.sleep(LINGER_S)  # and the clients' backlogs drain before the server stops
                return
            self.clock.sleep(POLL_S)

    # ---------------------------------------------------------------- loops
    def observe(self) -> None:
        """The same watch loop in both modes: the viewer takes part in no lockstep."""
        if threading.current_thread() is threading.main_thread():  # a process of its own, never a test's thread
            idle = self.lockstep_control and self.pace == 0
            self.log.info("viewer priority: %s", "; ".join(lower_priority(idle)))
        try:
            self.watch()
        finally:
            self.server.stop()

    def summary_extra(self) -> dict[str, object]:
        return {"port": self.port, "scenes": self.scenes, "referee_logs": self.logs}
