"""A match that pauses wherever a learner's robot needs an action.

The in-process engine (runtime/coop.py) runs every node of a match on one
thread, each node's lockstep generator resumed while the link it waits on is
ready. `SteppedMatch` has it build the very same nodes (`InProcess.stepped`), gives each learner's robot a
`LearnerBrain` whose action the caller sets, and puts one more wait into that
robot's loop: just before it acts at a decision tick k (its `sense` of k - L
and its latest `order` are in), it waits on a `Gate` that only the caller
opens. `advance()` runs the match until every learner waits at its gate (or
has ended), so the engine, the referee, the base stations and every other
robot play exactly as in `arena match`, and the learner's commands enter the
match where its strategy's would have. Digests are the distributed match's
(tests/unit/test_learn.py replays an episode through real processes).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import msgspec

from arena.config import MatchConfig, ProcessId
from arena.match import InProcess
from arena.runtime.coop import Task
from arena.schemas.messages import Order, Referee, Sense, World
from arena.strategies.base import RobotContext
from arena.strategies.learned import LearnerBrain

_referee = msgspec.msgpack.Decoder(Referee).decode
_world = msgspec.msgpack.Decoder(World).decode


class _Ball(msgspec.Struct, forbid_unknown_fields=False):
    """The fields of a `world` frame the reward needs: decoded without its robots."""

    tick: int
    ball_x: float
    ball_y: float


_ball = msgspec.msgpack.Decoder(_Ball).decode
# Set pieces: play stops and the named team restarts it (a kick-off is not one: it follows a goal or a half).
RESTARTS = frozenset({"FREEKICK", "GOALKICK", "THROWIN", "CORNER", "PENALTY"})
# The commands that leave the command in force as it is.
KEEPS_PLAY = frozenset({"YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW", "REPAIR_OUT"})


@dataclass(frozen=True)
class Restart:
    """A set piece the referee called: `name` for `team`; `banked` [m]: the ball's in-play progress towards
    team a's opponent goal line since play last started, up to the call (team b's is its negative)."""

    name: str
    team: str
    tick: int
    banked: float


class InPlay:
    """The ball's progress while it is in play (the referee's command in force is START), tick by tick.

    `world` frames come every tick, the referee's every few; a frame's movement is judged once the
    referee's frames have come up to its tick, so a ball that a step plays over a line and the referee
    then places elsewhere never counts its way back or its placement."""

    def __init__(self):
        self.events: list[tuple[int, int, Any]] = []  # (tick, order, command or frame state), by tick
        self.balls: list[_Ball] = []
        self.judged_to = -1  # the referee's frames have come up to this tick
        self.in_play = False
        self.dir_a = 1
        self.last: _Ball | None = None
        self.banked = 0.0
        self.sorted = True

    def referee(self, ref: Referee) -> None:
        for c in ref.commands:
            if c.name not in KEEPS_PLAY:
                self.events.append((c.tick, 0, c))
        self.events.append((ref.tick, 1, ref))
        self.sorted = False
        self.judged_to = max(self.judged_to, ref.tick)

    def world(self, raw: bytes) -> _Ball:
        b = _ball(raw)
        self.balls.append(b)
        return b

    def settle(self, everything: bool) -> tuple[float, list[Restart]]:
        """Team a's in-play progress [m] over the frames judged now (all of them: `everything`), and the
        set pieces called among them."""
        if not self.sorted:
            self.events.sort(key=lambda e: (e[0], e[1]))
            self.sorted = True
        events, balls = self.events, self.balls
        upto = balls[-1].tick if everything and balls else self.judged_to
        progress, restarts = 0.0, []
        i = n = 0
        last = self.last
        for b in balls:
            if b.tick > upto:
                break
            n += 1
            was = self.in_play
            while i < len(events) and events[i][0] <= b.tick:
                self._apply(events[i], restarts)
                i += 1
            if was and self.in_play and last is not None:
                d = (b.ball_x - last.ball_x) * self.dir_a
                progress += d
                self.banked += d
            last = b
        self.last = last
        if n:
            del balls[:n]
        if i:
            del events[:i]
        return progress, restarts

    def _apply(self, event: tuple[int, int, Any], restarts: list[Restart]) -> None:
        tick, kind, e = event
        if kind == 1:  # a referee frame: its state at its tick
            self.in_play = e.command == "START" and e.stage in ("FIRST_HALF", "SECOND_HALF")
            self.dir_a = e.attack_dir_a
        elif e.name in RESTARTS:  # charged once: the progress it ends is spent
            restarts.append(Restart(e.name, e.team, tick, self.banked))
            self.banked = 0.0
            self.in_play = False
        elif e.name == "START":
            self.in_play, self.banked = True, 0.0
        else:
            self.in_play = False


class Gate:
    """Where a learner's robot waits for its action; duck-types the `Inbound` a cooperative task parks on."""

    __slots__ = ("key", "sender", "paired", "released", "waiter", "channel", "waited")
    ready_below = -1  # no bound kept: a driver asks `ready(k)` (runtime/drivers.py `advance`)

    def __init__(self, name: str):
        self.key = f"action/{name}"
        self.sender = "learner"
        self.paired = False  # the robot puts its held-back `cmd` batch as it parks here
        self.released = -1  # the last tick whose action is set
        self.waiter: Task | None = None
        self.channel = self  # a parked task waits on it as on a link's channel
        self.waited = -1  # the tick a driver last waited on it for (runtime/drivers.py `advance` sets it)

    def ready(self, k: int) -> bool:
        return self.released >= k

    def drain(self) -> None:
        """Nothing arrives here: only `release` opens the gate."""

    def release(self, k: int, runnable) -> None:
        self.released = k
        if self.waiter is not None:
            runnable.append(self.waiter)
            self.waiter = None


def _gated(node, gate: Gate, skip: int) -> Iterator[Any]:
    """The robot's own lockstep loop, with a wait on `gate` before it acts at every `skip`-th tick.

    A robot acts right after its `order` link is ready for that tick (processes/robot.py)."""
    order_in = node.order_in
    for w in node.lockstep():
        yield w
        if w[0] is order_in and w[1] % skip == 0:
            yield gate, w[1]


class SteppedMatch:
    """One match, played up to each decision tick of its learners. `learners`: robot ids like "a/1"."""

    def __init__(
        self, cfg: MatchConfig, learners: list[str], frame_skip: int = 1, discrete: bool = False, keep: bool = False
    ):
        """`keep`: keep every `world` and `referee` frame (`worlds`, `referees`), to judge a scenario."""
        self.cfg = cfg
        self.keep = keep
        self.worlds: list[World] = []
        self.referees: list[Referee] = []
        self.frame_skip = frame_skip
        self.stepped = match = InProcess().stepped(cfg, watch=("referee", "world"), match="learn")
        self.bus = match.bus
        self.referee_ch, self.world_ch = match.taps["referee"], match.taps["world"]
        self.nodes = match.nodes
        self.actions: dict[str, Any] = {}
        self.gates: dict[str, Gate] = {}
        self.robot_of: dict[str, Any] = {}
        tasks = []
        for name, node in self.nodes.items():
            steps = node.lockstep()
            agent = ProcessId.parse(name).short if node.pid.kind == "robot" else ""
            if agent in learners:
                ctx = RobotContext(cfg=cfg, team=node.pid.team, n=node.pid.robot, rng=node.rng("strategy"))
                node.brain = LearnerBrain(ctx, self._decider(agent), frame_skip, discrete)
                self.gates[agent] = gate = Gate(agent)
                self.robot_of[agent] = node
                steps = _gated(node, gate, frame_skip)
            else:  # no gate on its waits: it may skip those already ready (`Node.skip_below`)
                node.skip_below = 1 << 62
            task = node.driver  # its `Task`; the gated loop is driven, not `Node.playing`
            task.steps, task.flush = steps, node.batch_flusher()
            tasks.append(task)
        self.tasks = tasks
        self.learner_tasks = {a: next(t for t in tasks if t.name == f"robot/{a}") for a in learners}
        self.tick = 0  # the decision tick the learners wait at
        self.score = (0, 0)
        self.attack_dir_a = 1
        self.ball: tuple[float, float] | None = None
        self.referee: Referee | None = None
        self.new_commands: list = []
        self.inplay = InPlay()
        self.world_raw: bytes | None = None  # the latest `world` frame, as sent
        self.progress_a = 0.0  # team a's in-play ball progress [m] over the frames the last `advance` judged
        self.restarts: list[Restart] = []
        self.bus.runnable.extend(tasks)

    def _decider(self, agent: str):
        return lambda _k, _sense, _order: self.actions[agent]

    @property
    def over(self) -> bool:
        for t in self.learner_tasks.values():
            if not t.done:
                return False
        return True

    def advance(self) -> None:
        """Play until every learner waits at its gate or has ended; then read the referee and the ball."""
        self.stepped.run()
        waiting = [t for t in self.learner_tasks.values() if not t.done]
        for t in waiting:
            if t.waiting is None or not isinstance(t.waiting[0], Gate):
                stuck = ", ".join(f"{x.name} on {x.waiting[0].key}" for x in self.tasks if x.waiting and not x.done)
                raise RuntimeError(f"the match stopped with no learner waiting for an action: {stuck}")
        if waiting:
            self.tick = waiting[0].waiting[1]  # type: ignore[index]
        self.new_commands = []
        while (raw := self.referee_ch.try_recv()) is not None:
            ref = _referee(raw)
            if self.keep:
                self.referees.append(ref)
            self.referee = ref
            self.score = (ref.score_a, ref.score_b)
            self.attack_dir_a = ref.attack_dir_a
            self.new_commands.extend(ref.commands)
            self.inplay.referee(ref)
        last = ball = None
        while (raw := self.world_ch.try_recv()) is not None:
            last = raw
            ball = self.inplay.world(raw)  # the ball's fields alone: no robots decoded a step
            if self.keep:
                self.worlds.append(_world(raw))
        if ball is not None:
            self.world_raw = last
            self.ball = (ball.ball_x, ball.ball_y)
        self.progress_a, self.restarts = self.inplay.settle(everything=self.over)

    def act(self, actions: dict[str, Any]) -> None:
        """Set the learners' actions for the tick they wait at and let them go on."""
        runnable = self.bus.runnable
        for agent, gate in self.gates.items():
            if agent in actions:
                self.actions[agent] = actions[agent]
            gate.release(self.tick, runnable)

    def seen(self, agent: str) -> tuple[Sense | None, Order | None]:
        """What the learner's robot acts on at the current decision tick."""
        node = self.robot_of[agent]
        k = min(self.tick, self.cfg.total_ticks)
        return node.sense_in.latest_by(k), node.order_in.latest_by(k)

    def world(self) -> World | None:
        """The latest ground truth (`world`), None before the first."""
        return None if self.world_raw is None else _world(self.world_raw)

    def digests(self) -> dict[str, str]:
        """Every process's digest of what it has sent so far."""
        return {name: node.digest.hexdigest() for name, node in self.nodes.items()}
