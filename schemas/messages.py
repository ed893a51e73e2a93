"""The wire messages: one typed msgpack map per data pair of the IRIS diagram.

Each message is a msgspec Struct encoded as a msgpack *map* with the field
names as keys, so any stock msgpack library can read and write it. Every
message carries `tick`: the control tick (default 20 ms) at which it was sent.
Units are SI. Frames:

* field frame: origin at the centre spot, x along the length towards the goal
  that team a attacks in the first half, y to the left of x, z up; theta is
  measured from +x, counter-clockwise, in (-pi, pi].
* body frame: x forward (the dribbler side), y to the robot's left.

Schema evolution (msgspec's rules, kept here too): a new field gets a default;
a field's type never changes; a field is never renamed.

The `Annotated` descriptions are the source of schemas/README.md; run
`arena schemas --write` after changing anything here.
"""

from typing import Annotated, Literal

import msgspec
from msgspec import Meta, Struct

from arena.schemas.vocabulary import RefCommandName, StageName, Team, TeamOrNone

# ---------------------------------------------------------------- field types
Tick = Annotated[int, Meta(ge=0, description="control tick at which the message was sent")]
Meters = Annotated[float, Meta(description="[m]")]
MetersPerSecond = Annotated[float, Meta(description="[m/s]")]
Radians = Annotated[float, Meta(description="[rad]")]
RadPerSecond = Annotated[float, Meta(description="[rad/s]")]


class Base(Struct, kw_only=True, forbid_unknown_fields=False, gc=False):
    """Common base: maps with named fields; unknown fields are ignored (evolution).

    `gc=False`: a message is plain data (numbers, strings, lists of messages), never part of a
    reference cycle, so the cyclic collector need not track it: ~50 are built and decoded a tick,
    and a tracked one costs its allocation, its release and the collections it brings about."""


class Pose(Base):
    x: Annotated[float, Meta(description="[m] field frame")]
    y: Annotated[float, Meta(description="[m] field frame")]
    theta: Annotated[float, Meta(description="[rad] heading from +x, CCW")]


class BallSeen(Base):
    visible: Annotated[bool, Meta(description="false: no detection, x/y are meaningless")] = False
    x: Annotated[float, Meta(description="[m] field frame")] = 0.0
    y: Annotated[float, Meta(description="[m] field frame")] = 0.0


class RobotSeen(Base):
    team: Annotated[Team, Meta(description="team colour seen on the robot")]
    x: Annotated[float, Meta(description="[m] field frame")]
    y: Annotated[float, Meta(description="[m] field frame")]


# ------------------------------------------------------------------- S_G / G_S
class FieldSpec(Base):
    """S_G: the field's geometry, sent once by the engine at tick 0."""

    tick: Tick
    length: Annotated[float, Meta(description="[m] goal line to goal line")]
    width: Annotated[float, Meta(description="[m] touch line to touch line")]
    runoff: Annotated[float, Meta(description="[m] lines to fence")]
    goal_width: Annotated[float, Meta(description="[m] between the posts")]
    goal_height: Annotated[float, Meta(description="[m] crossbar height")]
    goal_depth: Annotated[float, Meta(description="[m] net depth")]
    center_circle_radius: Meters
    penalty_area_depth: Meters
    penalty_area_width: Meters
    goal_area_depth: Meters
    goal_area_width: Meters
    penalty_mark_distance: Annotated[float, Meta(description="[m] from the goal line")]
    robots_per_team: Annotated[int, Meta(description="robots per team, goalkeeper (0) included")]
    dt: Annotated[float, Meta(description="[s] control tick length")]
    total_ticks: Annotated[int, Meta(description="last tick of the match")]


# ---------------------------------------------------------------------- G_R_n
class Sense(Base):
    """G_R_n: what robot n's sensors report at this tick. Never ground truth."""

    tick: Tick
    pose: Annotated[Pose, Meta(description="noisy self-localisation, field frame")]
    vx: Annotated[float, Meta(description="[m/s] odometry, body frame")] = 0.0
    vy: Annotated[float, Meta(description="[m/s] odometry, body frame")] = 0.0
    omega: Annotated[float, Meta(description="[rad/s] odometry")] = 0.0
    ball: Annotated[BallSeen, Meta(description="noisy, range-limited ball detection")] = msgspec.field(
        default_factory=BallSeen
    )
    robots: Annotated[list[RobotSeen], Meta(description="noisy, range-limited robot detections")] = []
    has_ball: Annotated[bool, Meta(description="the dribbler holds the ball")] = False


# ---------------------------------------------------------------------- R_n_G
class Cmd(Base):
    """R_n_G: robot n's actuator command. Applied by the engine from tick+1 on."""

    tick: Tick
    mode: Annotated[Literal["body", "wheels"], Meta(description="which of the two velocity forms is meant")] = "body"
    vx: Annotated[float, Meta(description="[m/s] body frame, mode=body")] = 0.0
    vy: Annotated[float, Meta(description="[m/s] body frame, mode=body")] = 0.0
    omega: Annotated[float, Meta(description="[rad/s] mode=body")] = 0.0
    wheels: Annotated[list[float], Meta(description="[rad/s] wheel speeds, mode=wheels")] = []
    dribbler: Annotated[bool, Meta(description="dribbler on")] = False
    kick_speed: Annotated[float, Meta(ge=0.0, description="[m/s] 0 = no kick; capped by the robot's kicker")] = 0.0
    kick_lob: Annotated[bool, Meta(description="lob kick (ballistic z) instead of a flat kick")] = False


# ---------------------------------------------------------------------- R_n_B
class Report(Base):
    """R_n_B (eq. 5): robot n tells its base station what it knows."""

    tick: Tick
    robot: Annotated[int, Meta(ge=0, description="robot number n")]
    pose: Annotated[Pose, Meta(description="the robot's own pose estimate")]
    ball: BallSeen = msgspec.field(default_factory=BallSeen)
    robots: Annotated[list[RobotSeen], Meta(description="robots it detects (P_A, P_B)")] = []
    has_ball: bool = False
    role: Annotated[str, Meta(description="the role the robot is playing")] = ""


# ---------------------------------------------------------------------- B_R_n
class TeamPose(Base):
    robot: Annotated[int, Meta(description="robot number, -1 if unknown (opponents)")]
    x: Meters
    y: Meters
    theta: Radians = 0.0
    age: Annotated[int, Meta(description="[ticks] since last seen")] = 0
    role: Annotated[str, Meta(description="own robots: the role the base station gave it, '' otherwise")] = ""


class Order(Base):
    """B_R_n (eq. 5): base station to robot n: P_A, P_B, P_ball, C, S and roles."""

    tick: Tick
    robot: Annotated[int, Meta(ge=0, description="robot number n")]
    command: Annotated[RefCommandName, Meta(description="C: current referee command (MSL RefBox name)")] = "STOP"
    command_team: Annotated[TeamOrNone, Meta(description="team the command is for, '' = both")] = ""
    spot_x: Annotated[float, Meta(description="[m] restart ball spot, field frame")] = 0.0
    spot_y: Annotated[float, Meta(description="[m] restart ball spot, field frame")] = 0.0
    attack_dir: Annotated[int, Meta(description="+1: this team attacks the +x goal now, -1: the -x goal")] = 1
    strategy: Annotated[
        int, Meta(ge=1, le=3, description="S: 1 level, 2 offensive (losing), 3 defensive (winning)")
    ] = 1
    role: Annotated[str, Meta(description="role for this robot: goalkeeper, defender, attacker")] = ""
    role_state: Annotated[int, Meta(description="Fig. 6 state 1-4, 0 for the goalkeeper")] = 0
    own: Annotated[list[TeamPose], Meta(description="P_A: fused poses of own robots")] = []
    opponents: Annotated[list[TeamPose], Meta(description="P_B: fused opponent positions")] = []
    ball_valid: bool = False
    ball_x: Annotated[float, Meta(description="[m] P_ball, field frame")] = 0.0
    ball_y: Annotated[float, Meta(description="[m] P_ball, field frame")] = 0.0
    ball_z: Annotated[float, Meta(description="[m] P_ball")] = 0.0
    ball_age: Annotated[int, Meta(description="[ticks] since the ball was last seen")] = 0


# ----------------------------------------------------------- Re_G / Re -> B
class RefCommand(Base):
    name: Annotated[RefCommandName, Meta(description="MSL RefBox command name")]
    team: Annotated[TeamOrNone, Meta(description="target team, '' = both")] = ""
    x: Annotated[float, Meta(description="[m] ball spot, field frame")] = 0.0
    y: Annotated[float, Meta(description="[m] ball spot, field frame")] = 0.0
    tick: Annotated[int, Meta(description="tick at which the referee issued it")] = 0
    robot: Annotated[
        int, Meta(description="YELLOW_CARD, RED_CARD, DOUBLE_YELLOW, REPAIR_OUT: the robot's number; else -1")
    ] = -1


class Referee(Base):
    """Re_G and referee to base stations: the referee box's state and new commands."""

    tick: Tick
    stage: Annotated[StageName, Meta(description="MSL RefBox stage")]
    command: Annotated[RefCommandName, Meta(description="the command in force (MSL RefBox name)")]
    command_team: TeamOrNone = ""
    spot_x: Meters = 0.0
    spot_y: Meters = 0.0
    score_a: Annotated[int, Meta(ge=0)] = 0
    score_b: Annotated[int, Meta(ge=0)] = 0
    attack_dir_a: Annotated[int, Meta(description="+1: team a attacks the +x goal now")] = 1
    commands: Annotated[list[RefCommand], Meta(description="commands issued since the previous message, in order")] = []


# ----------------------------------------------------------------------- G_Re
class BallEvent(Base):
    """One ball-status event; docs/rules.md says what the referee makes of each kind."""

    kind: Annotated[
        str,
        Meta(
            description="GOAL, TOUCH_LINE, GOAL_LINE, NO_PROGRESS, TOUCH, FOUL_PUSHING, FOUL_DRIBBLING, "
            "ROBOT_DEAD, ROBOT_STUCK"
        ),
    ]
    tick: Annotated[int, Meta(description="tick at which it happened")]
    team: Annotated[
        TeamOrNone,
        Meta(
            description="GOAL: scoring team; GOAL_LINE: the team defending that goal line; "
            "TOUCH: toucher's team; FOUL_*: offender's team; ROBOT_DEAD, ROBOT_STUCK: the robot's team"
        ),
    ] = ""
    robot: Annotated[int, Meta(description="robot involved (toucher, offender, dead robot), -1 if none")] = -1
    x: Annotated[float, Meta(description="[m] ball position, field frame; FOUL_PUSHING: contact point")] = 0.0
    y: Annotated[float, Meta(description="[m] ball position, field frame; FOUL_PUSHING: contact point")] = 0.0
    last_team: Annotated[TeamOrNone, Meta(description="team of the last robot to touch the ball")] = ""
    last_robot: Annotated[int, Meta(description="last robot to touch the ball, -1 if none")] = -1


class EngineEvents(Base):
    """G_Re: ball-status events since the previous message (may be empty)."""

    tick: Tick
    events: list[BallEvent] = []


# ------------------------------------------------------------------------ G_V
class RobotState(Base):
    team: Team
    robot: int
    x: Meters
    y: Meters
    theta: Radians
    vx: Annotated[float, Meta(description="[m/s] field frame")] = 0.0
    vy: Annotated[float, Meta(description="[m/s] field frame")] = 0.0
    omega: RadPerSecond = 0.0
    has_ball: bool = False


class World(Base):
    """G_V: ground truth for viewers and the recorder. Robots never read it."""

    tick: Tick
    t: Annotated[float, Meta(description="[s] simulated time")]
    ball_x: Meters
    ball_y: Meters
    ball_z: Meters = 0.0
    ball_vx: MetersPerSecond = 0.0
    ball_vy: MetersPerSecond = 0.0
    ball_vz: MetersPerSecond = 0.0
    robots: list[RobotState] = []
    last_team: TeamOrNone = ""
    last_robot: int = -1


# ------------------------------------------------------------- B_RefBox
class Worldstate(Base):
    """A base station's worldstate as the MSL RefBox bridge received and validated it (docs/refbox.md)."""

    tick: Annotated[int, Meta(ge=0, description="the bridge's match tick when the message was complete")]
    team: Team
    address: Annotated[str, Meta(description="the base station's IP address")] = ""
    age_ms: Annotated[float, Meta(description="[ms] the message's ageMs")] = 0.0
    json: Annotated[str, Meta(description="the worldstate JSON exactly as the base station sent it")] = ""


# --------------------------------------------------------- infrastructure
class Summary(Base):
    """End of match: one per process, for the launcher's JSON summary."""

    tick: Tick
    process: Annotated[str, Meta(description="e.g. robot/a/1")]
    pid: Annotated[int, Meta(description="OS process id")]
    digest: Annotated[str, Meta(description="hex BLAKE2b of every (key, payload) it sent, in order")]
    sent: Annotated[int, Meta(description="frames sent")]
    rejected: Annotated[int, Meta(description="malformed, too-large, out-of-sequence, conflicting or invalid inputs")]
    rejected_reasons: dict[str, int] = {}
    links: Annotated[
        dict[str, dict[str, float]],
        Meta(description="per inbound link class: frames, dropped, delay_ms_sum"),
    ] = {}
    delays_ms: Annotated[dict[str, list[float]], Meta(description="per link class: drawn delays [ms]")] = {}
    dead: Annotated[list[str], Meta(description="peers that went silent and were treated as dead")] = []
    tick_us: Annotated[list[float], Meta(description="[us] median and p95 wall time per tick of own work")] = []
    wall_s: Annotated[float, Meta(description="[s] wall time from the start barrier to the last tick")] = 0.0
    cpu_s: Annotated[list[float], Meta(description="[s] user and system CPU time of the whole process")] = []
    extra: Annotated[dict[str, object], Meta(description="kind-specific results (score, events, distances)")] = {}
    sent_by_key: Annotated[
        dict[str, int], Meta(description="frames sent per key, the key without the `arena/<match>/` prefix")
    ] = {}
    conflicts: Annotated[
        dict[str, int],
        Meta(description="per inbound key (no prefix): frames for a tick that already had a different frame"),
    ] = {}
    dead_at: Annotated[
        dict[str, int], Meta(description="per peer in `dead`: this process's tick when it stopped waiting for it")
    ] = {}
    forged: Annotated[
        dict[str, int],
        Meta(description="per inbound key (no prefix): frames dropped because their sender's MAC did not check out"),
    ] = {}


class TapFrame(Base):
    """One frame a process sent, as it went on the wire (for the recorder)."""

    key: Annotated[str, Meta(description="the key without the `arena/<match>/` prefix, e.g. robot/a/1/cmd")]
    tick: Annotated[int, Meta(ge=0, description="the frame's own tick")]
    payload: Annotated[bytes, Meta(description="the msgpack payload, byte for byte (msgpack bin)")]


class TapBatch(Base):
    """A recorded match only: the frames one process sent, batched every tap period.

    Every frame the process sent with a tick below `tick` is in this batch or
    an earlier one, in send order. The last batch has `final` set and comes
    before the process's `Summary`.
    """

    tick: Annotated[int, Meta(ge=0, description="watermark: no later frame of this process has a lower tick")]
    process: Annotated[str, Meta(description="sender, e.g. robot/a/1")]
    seq: Annotated[int, Meta(ge=0, description="batch number of this process: 0, 1, 2, ...")]
    final: Annotated[bool, Meta(description="the process's last batch")] = False
    frames: list[TapFrame] = []


class Control(Base):
    """Viewer to engine, live lockstep matches only (`arena match --live`): pause, step, pace.

    The engine only waits on it, so it never changes what anybody sends.
    """

    tick: Annotated[int, Meta(ge=0, description="the newest tick the viewer has seen (for the logs)")]
    seq: Annotated[int, Meta(ge=0, description="increases with every frame of the viewer")]
    paused: Annotated[bool, Meta(description="hold the engine before its next tick")] = False
    step: Annotated[int, Meta(ge=0, le=1_000_000, description="paused: play this many more ticks, then hold")] = 0
    pace: Annotated[
        float, Meta(ge=-1.0, le=1000.0, description="simulated seconds per wall second, 0 unpaced, -1 unchanged")
    ] = -1.0


# ------------------------------------------------------------- scenario control
# Control as messages (the SSL simulation protocol's SimulatorControl): each is applied at one
# tick, by the engine (teleports) or by the referee (overrides), so its effect is in every frame
# sent after it and in the digest. A scenario (docs/scenarios.md) carries them in its steps.
OptMeters = Annotated[float | None, Meta(description="[m] field frame; none: keep the current value")]
OptSpeed = Annotated[float | None, Meta(description="[m/s] field frame; none: keep the current value")]


class TeleportBall(Base, tag="teleport_ball"):
    """Put the ball somewhere (SSL `TeleportBall`); unset fields keep their current value."""

    x: OptMeters = None
    y: OptMeters = None
    z: Annotated[float, Meta(ge=0.0, description="[m] height; above 0 the ball flies from there")] = 0.0
    vx: OptSpeed = None
    vy: OptSpeed = None
    vz: Annotated[float, Meta(description="[m/s] vertical speed")] = 0.0
    by_force: Annotated[
        bool,
        Meta(description="no jump: the ball is rolled towards (x, y) so that rolling friction stops it there"),
    ] = False
    safely: Annotated[
        bool, Meta(description="SSL teleport_safely: the nearest spot to (x, y) clear of every robot")
    ] = False
    roll: Annotated[bool, Meta(description="SSL roll: on the ground and rolling (z and vz ignored), not flying")] = (
        False
    )


class TeleportRobot(Base, tag="teleport_robot"):
    """Put one robot somewhere, or take it off the field (SSL `TeleportRobot`)."""

    team: Team
    robot: Annotated[int, Meta(ge=0, description="robot number")]
    x: OptMeters = None
    y: OptMeters = None
    orientation: Annotated[float | None, Meta(description="[rad] heading; none: keep it")] = None
    vx: OptSpeed = None
    vy: OptSpeed = None
    omega: Annotated[float | None, Meta(description="[rad/s]; none: keep it")] = None
    present: Annotated[
        bool, Meta(description="false: parked beyond the fence for the rest of the match (its process plays on)")
    ] = True
    by_force: Annotated[
        bool, Meta(description="no jump: the robot is pushed towards (x, y) at up to its max speed")
    ] = False
    safely: Annotated[
        bool,
        Meta(description="SSL teleport_safely: the nearest spot to (x, y) clear of other robots, the ball and goals"),
    ] = False


class ControlRobot(Base, tag="control"):
    """Drive one robot for `ticks` ticks with these body-frame velocities, kick and dribbler (SSL `RobotControl`);
    its own process's commands are ignored meanwhile."""

    team: Team
    robot: Annotated[int, Meta(ge=0, description="robot number")]
    ticks: Annotated[int, Meta(ge=1, description="[ticks] how long, from the step's tick")]
    vx: Annotated[float, Meta(description="[m/s] body frame, forward")] = 0.0
    vy: Annotated[float, Meta(description="[m/s] body frame, left")] = 0.0
    omega: Annotated[float, Meta(description="[rad/s]")] = 0.0
    kick_speed: Annotated[float, Meta(ge=0.0, description="[m/s] kick when the ball is in reach; 0: none")] = 0.0
    kick_lob: Annotated[bool, Meta(description="lob kick instead of a flat kick")] = False
    dribbler: Annotated[bool, Meta(description="dribbler on")] = False


class RefereeOverride(Base, tag="referee"):
    """A referee decision forced at a tick: the command, with the MSL set-piece procedure for set pieces."""

    command: Annotated[RefCommandName, Meta(description="MSL RefBox command name")]
    team: Annotated[TeamOrNone, Meta(description="target team, '' = both")] = ""
    x: Annotated[float | None, Meta(description="[m] ball spot; none: the rule's own spot for the ball")] = None
    y: Annotated[float | None, Meta(description="[m] ball spot; none: the rule's own spot for the ball")] = None
    robot: Annotated[int, Meta(description="cards and REPAIR_OUT: the robot's number; else -1")] = -1


class SetLink(Base, tag="link"):
    """Change the emulated links (runtime/links.py) for every frame sent from this tick on, at every receiver."""

    preset: Annotated[str, Meta(description="link preset: ideal, lan, wifi, congested-wifi")]
    overrides: Annotated[
        dict[str, dict[str, float]],
        Meta(description="per link class (sensor, wifi, wired), LinkModel parameters to change"),
    ] = {}


class KillProcess(Base, tag="kill"):
    """Stop a team's process at this tick, as if it had died: its loop ends before acting at the tick."""

    process: Annotated[str, Meta(description="robot/<team>/<n> or basestation/<team>")]


Action = TeleportBall | TeleportRobot | RefereeOverride | SetLink | KillProcess | ControlRobot


class Region(Base):
    """An axis-aligned rectangle of the field frame."""

    x0: Meters
    y0: Meters
    x1: Meters
    y1: Meters

    def contains(self, x: float, y: float) -> bool:
        return min(self.x0, self.x1) <= x <= max(self.x0, self.x1) and min(self.y0, self.y1) <= y <= max(
            self.y0, self.y1
        )


class Condition(Base):
    """What the engine watches for a step's `when`: every field that is set must hold."""

    ball_in: Annotated[Region | None, Meta(description="the ball's centre is in this region")] = None
    robot: Annotated[str, Meta(description="robot for `robot_in`, e.g. a/1")] = ""
    robot_in: Annotated[Region | None, Meta(description="`robot`'s centre is in this region")] = None
    command: Annotated[str, Meta(description="the engine has applied this referee command")] = ""
    possession: Annotated[TeamOrNone, Meta(description="a robot of this team holds the ball")] = ""


class Step(Base):
    """A scenario's step, carried in the match configuration (`scenario.steps`, docs/scenarios.md), on no key.

    Do `actions` once: at tick `at`, or at the first tick at which `when` holds.
    """

    at: Annotated[int, Meta(ge=-1, description="[ticks] when to act; -1: when `when` first holds")] = -1
    when: Annotated[Condition | None, Meta(description="the condition, if `at` is -1")] = None
    actions: list[Action] = []


class Operator(Base):
    """Operator to engine and referee, live sessions only (`--realtime` or `--live`; `arena operator`).

    The scenario messages, applied at the receiver's next tick: the engine takes the
    teleports, the referee the overrides. Both log what they applied, with the tick,
    in their summaries' `operator`, so a session can be written down as a scenario.
    """

    seq: Annotated[int, Meta(ge=0, description="increases with every frame of the operator")]
    actions: Annotated[list[TeleportBall | TeleportRobot | RefereeOverride], Meta(description="applied in order")] = []


MESSAGE_TYPES: tuple[type[Base], ...] = (
    FieldSpec,
    Sense,
    Cmd,
    Report,
    Order,
    Referee,
    EngineEvents,
    World,
    Worldstate,
    Summary,
    TapBatch,
    Control,
    Step,
    Operator,
)

_ENCODER = msgspec.msgpack.Encoder()


def encode(msg: Base) -> bytes:
    return _ENCODER.encode(msg)


def decoder(msg_type: type[Base]) -> msgspec.msgpack.Decoder:
    """A validating decoder for one message type (raises msgspec.DecodeError / ValidationError)."""
    return msgspec.msgpack.Decoder(msg_type)
