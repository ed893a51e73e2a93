"""Match configuration: frozen dataclasses with defaults, passed explicitly.

Every physical constant carries its unit next to it. The whole configuration
travels as JSON (``MatchConfig.to_json``/``from_json``), so every process of a
match, local or on a robot's own computer, plays from the very same numbers.

Field numbers (design.md section 7): a 12 m x 8 m playing area, 1 m run-off
enclosed by a fence, goals 2 m wide and 1 m high. The MSL rule book's areas
(22 m x 14 m field) are scaled down and rounded; the chosen values are listed in
docs/field.md. The game rules' numbers (`RulesParams`) are tabled in docs/rules.md.

The bottom room of the house but for the wire: may import `arena.schemas` only;
every package above imports it.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from typing import Any

import msgspec

from arena.schemas.keys import DEFAULT_PERIODS
from arena.schemas.messages import Step
from arena.schemas.vocabulary import TEAMS

MAX_HALF_TIME = 3600.0  # [s] the longest half a match accepts (an MSL half is 15 min)
MAX_PERCEPTION_LATENCY = 25  # [ticks] 0.5 s at 50 Hz: far beyond any real vision pipeline
MAX_DT = 0.1  # [s] a control tick of at most 100 ms (10 Hz): slower is no robot's control loop
MAX_SUBSTEPS = 100  # physics steps per tick
MAX_PERIOD_S = 1.0  # [s] the Wi-Fi, referee and world periods: slower plays no recognisable match
MIN_LEASE, MAX_LEASE = 0.5, 600.0  # [s] zenoh's keep-alive goes out every quarter lease: not faster than 125 ms
ParamValue = bool | int | float | str  # a strategy parameter's value (MatchConfig.params)
KINDS = ("engine", "referee", "basestation", "robot", "recorder", "refbox", "viewer")


@dataclass(frozen=True)
class FieldParams:
    length: float = 12.0  # [m] goal line to goal line
    width: float = 8.0  # [m] touch line to touch line
    runoff: float = 1.0  # [m] border between the lines and the fence
    goal_width: float = 2.0  # [m] inner distance between the posts
    goal_height: float = 1.0  # [m] crossbar height
    goal_depth: float = 0.5  # [m] net depth behind the goal line
    center_circle_radius: float = 1.0  # [m] MSL 2 m, scaled
    penalty_area_depth: float = 1.5  # [m] MSL 2.25 m, scaled
    penalty_area_width: float = 5.0  # [m] MSL 6.5 m, scaled
    goal_area_depth: float = 0.5  # [m] MSL 0.75 m, scaled
    goal_area_width: float = 3.0  # [m] MSL 3.9 m, scaled
    penalty_mark_distance: float = 2.0  # [m] from the goal line; MSL 3 m, scaled
    corner_arc_radius: float = 0.5  # [m]
    line_width: float = 0.125  # [m]


@dataclass(frozen=True)
class RobotParams:
    """The IRIS robot (paper 2): 45 x 45 cm, 37 kg, four omni wheels."""

    model: str = "omni4"  # omni4 (IRIS, paper 2 eq. 3-4) | omni3 (Robotino, paper 1 eq. 1-2)
    size: float = 0.45  # [m] square footprint side
    height: float = 0.70  # [m]
    mass: float = 37.0  # [kg]
    max_speed: float = 5.0  # [m/s]
    max_accel: float = 2.0  # [m/s^2]
    max_omega: float = 6.0  # [rad/s]
    max_alpha: float = 12.0  # [rad/s^2] angular acceleration limit
    wheel_radius: float = 0.05  # [m]
    wheel_base: float = 0.20  # [m] l: wheel to robot centre
    max_wheel_speed: float = 110.0  # [rad/s] saturation (5.5 m/s at the rim)
    kick_max_speed: float = 8.0  # [m/s] flat kick
    lob_angle: float = math.radians(45.0)  # [rad] launch elevation of a lob kick
    dribble_max_omega: float = 3.0  # [rad/s] turn rate above which the dribbler loses the ball
    cmd_timeout: float = 0.2  # [s] realtime mode: wheels stop after this long without a command


ROBOTINO = RobotParams(
    model="omni3",  # Festo Robotino, paper 1 eq. 1-2; design.md section 7
    size=0.37,  # [m] footprint (a 370 mm round base, boxed)
    height=0.32,  # [m]
    mass=20.0,  # [kg]
    max_speed=2.0,  # [m/s]
    max_accel=2.0,  # [m/s^2]
    max_omega=4.0,  # [rad/s]
    max_alpha=8.0,  # [rad/s^2]
    wheel_radius=0.04,  # [m] R, 80 mm omni wheels
    wheel_base=0.135,  # [m] L, centre to wheel
    max_wheel_speed=55.0,  # [rad/s] 2.2 m/s at the rim
    kick_max_speed=4.0,  # [m/s]
)
"""The Robotino of paper 1 as a drop-in `MatchConfig.robot`; numbers the paper lacks are Festo's or assumed."""

EPUCK = RobotParams(
    model="diff",  # differential drive, paper 3 eq. 8 and 13 (navigation/diffdrive.py)
    size=0.074,  # [m] footprint: the E-puck is round, radius 37 mm (paper 3 sec. II-C), boxed
    height=0.05,  # [m]
    mass=0.15,  # [kg] assumed; not in paper 3
    max_speed=0.13,  # [m/s] just above the rim speed of max_wheel_speed (0.129 m/s), so the wheels limit
    max_accel=1.0,  # [m/s^2] assumed; high, so that the body follows eq. 8's kinematic model closely
    max_omega=5.0,  # [rad/s] just above 2 R max_wheel_speed / L (4.95 rad/s), so the wheels limit
    max_alpha=40.0,  # [rad/s^2] assumed, as max_accel
    wheel_radius=0.0205,  # [m] R, E-puck wheel (navigation/diffdrive.py)
    wheel_base=0.026,  # [m] wheel to robot centre: half the 52 mm axle length L
    max_wheel_speed=6.28,  # [rad/s] the E-puck motor limit (Webots' MAX_SPEED)
    kick_max_speed=0.0,  # [m/s] no kicker
)
"""The E-puck of paper 3 (`arena bench nav`). Its model "diff" is the engine's
differential drive (`sim/drive.py`); `MatchConfig.validate` still
accepts only the soccer robots omni4 and omni3 for matches."""


@dataclass(frozen=True)
class BallParams:
    """Size-5 football."""

    radius: float = 0.11  # [m]
    mass: float = 0.43  # [kg]
    rolling_decel: float = 0.4  # [m/s^2] rolling friction on carpet
    restitution: float = 0.6  # [-] against fence, posts and robots


@dataclass(frozen=True)
class SensorParams:
    """The paper's 360-degree LIDAR-like sensor: noisy, range-limited detections."""

    pose_sigma: float = 0.02  # [m] self-localisation noise (1 sigma)
    heading_sigma: float = 0.01  # [rad]
    ball_range: float = 6.0  # [m] beyond this the ball is not detected
    robot_range: float = 5.0  # [m]
    det_sigma: float = 0.03  # [m] detection noise at 0 m
    det_sigma_per_m: float = 0.01  # [m/m] detection noise growth with range


@dataclass(frozen=True)
class RulesParams:
    """The game rules the engine and the referee box enforce (docs/rules.md).

    Numbers follow the MSL rule book. Its 3 m set-piece distance belongs to a
    22 m x 14 m field and would scale to 1.6 m here; we keep a floor of 2 m.
    """

    kickoff_time: float = 1.0  # [s] positioning time between KICKOFF and START
    setpiece_time: float = 2.0  # [s] positioning time between a set-piece command and START
    take_time: float = 5.0  # [s] after START a set piece must be taken, else DROP_BALL
    setpiece_distance: float = 2.0  # [m] opponents' centres from the ball spot (MSL 3 m, scaled, >= 2 m)
    drop_ball_distance: float = 1.0  # [m] every robot's centre from a dropped ball (MSL 1 m)
    no_progress_s: float = 10.0  # [s] ball in play idle or stuck this long -> NO_PROGRESS -> DROP_BALL
    progress_radius: float = 0.5  # [m] the ball makes no progress while it stays within this of one point
    push_speed: float = 1.5  # [m/s] closing speed at robot-robot impact above which it is pushing
    dribble_limit: float = 3.0  # [m] MSL: straight-line carry from where the dribbler took the ball
    drop_ball_inset: float = 1.0  # [m] a dropped ball is put this far inside the lines
    spot_inset: float = 0.5  # [m] free kicks and throw-ins stay this far from the lines they do not lie on
    corner_inset: float = 0.25  # [m] corner kick spot, from both lines (inside the corner arc)
    yellow_fouls: int = 2  # a robot's 2nd foul: YELLOW_CARD; its 4th (2 x this): DOUBLE_YELLOW, sent off
    red_fouls: int = 0  # a robot's foul number this many: RED_CARD, sent off (0: never)
    stuck_s: float = 20.0  # [s] driven but within stuck_radius this long: ROBOT_STUCK -> REPAIR_OUT (0: never)
    stuck_radius: float = 0.2  # [m] see stuck_s


DEFAULT_PERCEPTION_LATENCY = 3  # [ticks] 60 ms at 50 Hz


@dataclass(frozen=True)
class TimingParams:
    dt: float = 0.02  # [s] control tick (50 Hz)
    substeps: int = 5  # physics steps per tick (250 Hz)
    comm_period: int = DEFAULT_PERIODS["comm"]  # [ticks] robot <-> base station Wi-Fi period (10 Hz)
    referee_period: int = DEFAULT_PERIODS["referee"]  # [ticks] engine events -> referee -> everyone (10 Hz)
    world_period: int = DEFAULT_PERIODS["world"]  # [ticks] ground-truth `world` for viewers and the recorder
    # The perception latency L is the model (omni-vision pipelines of MSL robots: 30-60 ms;
    # docs/architecture.md): 3 ticks, 60 ms (0: a robot that sees the present). The batch is a transport detail: the digests are the same for every batch.
    # 0 and 0 are allowed (no latency; as many frames as L allows, L or 1).
    perception_latency: int = DEFAULT_PERCEPTION_LATENCY  # [ticks] a robot at tick k sees the `sense` of k - L
    batch: int = 0  # [frames] `sense`/`cmd` frames per message in lockstep (0: L, or 1)
    startup_timeout: float = 30.0  # [s] wall: wait for every process to come up
    # [s] wall: last-resort bound on one lockstep wait. Dead and hung peers are
    # caught by liveliness (~2 s, runtime/session.py); this catches a peer that
    # is alive but silent. Long, because everyone downstream of a stalled peer
    # waits too and must not be taken for dead.
    wait_timeout: float = 60.0
    # The zenoh link lease of every process that opens its session knowing this configuration
    # (runtime/session.py): a hung process's liveliness token vanishes this long after it was
    # last heard. 2 s lost healthy peers on an overloaded host; 0.5 s at least.
    lease: float = 6.0  # [s] wall: a process unheard this long (SIGSTOP, power loss, cut cable) is gone
    # `arena match` waits for every summary (a summary is put again for up to 5 s until acknowledged).
    summary_grace: float = 6.0  # [s] wall: for the summary of a process that exited or whose token vanished
    finish_grace: float = 10.0  # [s] wall: for the last summary, once every other process has sent its own

    def frames_per_message(self, realtime: bool = False) -> int:
        """`sense`/`cmd` frames per message: `batch`, or L when 0; always 1 in real time.

        At most L: the engine's batch for ticks k..k+n-1 needs the commands of up to
        k+n-2, which the robots send once they have the senses of up to k+n-2-L; with
        n <= L those came in an earlier batch. A node's batch is also put early, as it
        is, whenever the node is about to wait on any other link (`Outbound`): through
        the referee and the base stations a robot's `cmd` can wait on the engine's
        progress too.
        """
        if realtime:
            return 1
        return self.batch or max(1, self.perception_latency)

    def periods(self) -> dict[str, int]:
        """The periods the key table's schedules name (schemas/keys.py `Timing`), in ticks."""
        return {"tick": 1, "comm": self.comm_period, "referee": self.referee_period, "world": self.world_period}


@dataclass(frozen=True)
class RefboxTeam:
    """One row of a RefBox team table (msl_teams.json's keys, plus our `side` and `protocol`)."""

    address: str  # UnicastAddr, "a.b.c.*"
    name: str = ""  # Team
    target: str = ""  # MulticastAddr: the targetTeam of this team's commands
    side: str = ""  # "a", "b" or "" (the first free side)
    protocol: str = "json"  # json | legacy


@dataclass(frozen=True)
class RefboxParams:
    """The MSL RefBox bridge (docs/refbox.md). Nothing here changes a lockstep digest."""

    listen: str = ""  # tcp/HOST:PORT: run the bridge process there; "" for no bridge
    teams: tuple[RefboxTeam, ...] = ()  # team table; empty: first connection a, second b
    protocol_a: str = "json"  # without a table: the protocol of team a's connection (json | legacy)
    protocol_b: str = "json"
    swap: bool = False  # team a is magenta and b cyan (default: a cyan, b magenta)
    target_cyan: str = "224.16.32.201"  # targetTeam of cyan's commands when no table row names one
    target_magenta: str = "224.16.32.202"
    wait: int = 0  # hold the start until this many base stations are connected (0: never wait)
    follow: str = ""  # HOST:PORT of a real RefBox whose commands our referee mirrors; "" to decide itself
    via: bool = False  # our base stations take their referee commands over TCP from the bridge


@dataclass(frozen=True)
class ScenarioParams:
    """A scenario's start and steps (scenarios/, docs/scenarios.md). The defaults are a plain match.

    The engine and the referee read it at construction; `steps` are applied at
    their ticks inside the lockstep, so a scenario is as deterministic as a match.
    """

    ticks: int = 0  # [ticks] the run's last tick (END_GAME); 0: the two halves
    clock: int = 0  # [ticks] of match time already played at tick 0 (half time comes that much earlier)
    stage: str = ""  # the referee's stage at tick 0: FIRST_HALF or SECOND_HALF; "": PRE_GAME and the usual kick-off
    score: tuple[int, int] = (0, 0)  # goals of team a, team b at tick 0
    attack_dir_a: int = 1  # +1: team a attacks the +x goal at tick 0
    steps: tuple[Step, ...] = ()  # teleports and referee overrides, by tick or condition

    @property
    def active(self) -> bool:
        return self != ScenarioParams()


@dataclass(frozen=True)
class MatchConfig:
    seed: int = 0
    home: str = "basic-static"  # strategy of team a
    away: str = "basic-static"  # strategy of team b
    robots: int = 3  # per team, goalkeeper (robot 0) included
    half_time: float = 300.0  # [s] simulated
    link: str = "ideal"  # link preset name (runtime/links.py)
    link_overrides: dict[str, dict[str, float]] = field(default_factory=dict)
    realtime: bool = False
    external: tuple[str, ...] = ()  # processes started by hand, e.g. "robot/a/1"
    tap: bool = False  # the match records: every process taps what it sends (the MCAP path is the recorder's own)
    live: int = -1  # [-] TCP port of the live viewer's Foxglove server (processes/viewer.py); -1: no viewer, 0: any
    pace: float = 0.0  # [-] lockstep with a viewer: simulated seconds per wall second; 0: as fast as it goes
    # Strategy parameters per team ("a", "b"): name -> value, over the strategy's declared defaults
    # (strategies/base.py `Param`; `arena strategies --params NAME`). Empty: every default, as before.
    params: dict[str, dict[str, ParamValue]] = field(default_factory=dict)
    field: FieldParams = FieldParams()
    robot: RobotParams = RobotParams()
    ball: BallParams = BallParams()
    sensor: SensorParams = SensorParams()
    timing: TimingParams = TimingParams()
    rules: RulesParams = RulesParams()
    refbox: RefboxParams = RefboxParams()
    scenario: ScenarioParams = ScenarioParams()

    # ----------------------------------------------------------------- derived
    @property
    def half_ticks(self) -> int:
        return int(round(self.half_time / self.timing.dt))

    @property
    def total_ticks(self) -> int:
        """Ticks 0..total_ticks are played; the last one is END_GAME."""
        whole = 2 * self.half_ticks - self.scenario.clock
        return min(self.scenario.ticks, whole) if self.scenario.ticks > 0 else whole

    def strategy_of(self, team: str) -> str:
        return self.home if team == "a" else self.away

    def processes(self) -> list[ProcessId]:
        """Every process of the match, in the canonical order used for digests."""
        out = [ProcessId("engine"), ProcessId("referee")]
        for team in TEAMS:
            out.append(ProcessId("basestation", team))
        for team in TEAMS:
            for n in range(self.robots):
                out.append(ProcessId("robot", team, n))
        if self.refbox.listen:
            out.append(ProcessId("refbox"))
        if self.tap:
            out.append(ProcessId("recorder"))
        if self.live >= 0:
            out.append(ProcessId("viewer"))
        return out

    # ------------------------------------------------------------- (de)serial
    def to_dict(self) -> dict[str, Any]:
        return msgspec.to_builtins(self)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> MatchConfig:
        """Validate and build; raises ConfigError with a readable reason."""
        try:
            cfg = msgspec.convert(data, cls, strict=False)
        except msgspec.ValidationError as exc:
            raise ConfigError(f"invalid match configuration: {exc}") from None
        cfg.validate()
        return cfg

    @classmethod
    def from_json(cls, text: str) -> MatchConfig:
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ConfigError(f"match configuration is not JSON: {exc}") from None
        except RecursionError:  # the parser recurses per level: 100,000 `[` is no configuration
            raise ConfigError("match configuration nests arrays or objects too deep") from None
        if not isinstance(data, dict):
            raise ConfigError("match configuration must be a JSON object")
        return cls.from_dict(data)

    def replace(self, **changes: Any) -> MatchConfig:
        cfg = dataclasses.replace(self, **changes)
        cfg.validate()
        return cfg

    def validate(self) -> None:  # noqa: C901, PLR0912 - one check per configuration range, each one line
        if not 1 <= self.robots <= 6:
            raise ConfigError(f"--robots must be between 1 and 6, got {self.robots}")
        if not self.half_time > 0:
            raise ConfigError(f"--half-time must be positive, got {self.half_time}")
        if not self.half_time <= MAX_HALF_TIME:  # also catches inf and nan
            raise ConfigError(f"--half-time must be at most {MAX_HALF_TIME:g} s per half, got {self.half_time}")
        t = self.timing  # before anything divides by dt
        if not (math.isfinite(t.dt) and 0 < t.dt <= MAX_DT) or not 1 <= t.substeps <= MAX_SUBSTEPS:
            raise ConfigError(
                f"timing: dt must be in (0, {MAX_DT:g}] s and substeps in 1..{MAX_SUBSTEPS}, got {t.dt} and {t.substeps}"
            )
        longest = max(1, round(MAX_PERIOD_S / t.dt))  # a referee once a day would never start play
        for name in ("comm_period", "referee_period", "world_period"):
            if not 1 <= getattr(t, name) <= longest:
                raise ConfigError(
                    f"timing.{name} must be 1 tick to {MAX_PERIOD_S:g} s ({longest} ticks of {t.dt:g} s), "
                    f"got {getattr(t, name)}"
                )
        if self.half_ticks < 1:
            raise ConfigError(f"--half-time {self.half_time} is shorter than one tick")
        sc = self.scenario
        if sc.ticks < 0 or not 0 <= sc.clock < 2 * self.half_ticks:
            raise ConfigError(f"scenario: ticks must be >= 0 and clock within the match, got {sc.ticks}, {sc.clock}")
        if sc.stage not in ("", "FIRST_HALF", "SECOND_HALF") or sc.attack_dir_a not in (1, -1):
            raise ConfigError(f"scenario: stage {sc.stage!r} or attack_dir_a {sc.attack_dir_a} is not one to start in")
        if not 0 <= t.perception_latency <= MAX_PERCEPTION_LATENCY:
            raise ConfigError(
                f"--perception-latency must be 0..{MAX_PERCEPTION_LATENCY} ticks, got {t.perception_latency}"
            )
        if not 0 <= t.batch <= max(1, t.perception_latency):
            raise ConfigError(
                f"--batch must be 0 (auto) or 1..{max(1, t.perception_latency)} (at most the perception "
                f"latency, else the engine and the robots would wait for each other), got {t.batch}"
            )
        for name in ("startup_timeout", "wait_timeout", "summary_grace", "finish_grace"):
            value = getattr(t, name)
            if not (math.isfinite(value) and value > 0):
                raise ConfigError(f"timing.{name} must be a finite number of seconds > 0, got {value}")
        if not (math.isfinite(t.lease) and MIN_LEASE <= t.lease <= MAX_LEASE):
            raise ConfigError(f"timing.lease must be {MIN_LEASE:g} to {MAX_LEASE:g} s, got {t.lease}")
        if self.robot.model not in ("omni4", "omni3"):
            raise ConfigError(f"robot.model must be omni4 or omni3, got {self.robot.model!r}")
        if not 0 <= self.seed < 2**63:
            raise ConfigError(f"--seed must be in [0, 2^63), got {self.seed}")
        rb = self.refbox
        for side, proto in (("a", rb.protocol_a), ("b", rb.protocol_b)):
            if proto not in ("json", "legacy"):
                raise ConfigError(f"refbox protocol of team {side} must be json or legacy, got {proto!r}")
        if not 0 <= rb.wait <= 2:
            raise ConfigError(f"--refbox-wait must be 0, 1 or 2, got {rb.wait}")
        if rb.via and not rb.listen:
            raise ConfigError("--via-refbox needs the bridge: add --refbox [ENDPOINT]")
        if rb.via and not self.realtime:
            raise ConfigError(
                "--via-refbox needs --realtime: the RefBox protocol carries no tick, so a command read from "
                "TCP cannot be given the lockstep tick it belongs to (docs/refbox.md)"
            )
        if rb.follow and not self.realtime:
            raise ConfigError(
                "--refbox-follow needs --realtime: a human referee decides in wall-clock time, and the RefBox "
                "protocol carries no tick to play a command at in lockstep (docs/refbox.md)"
            )
        if rb.via and rb.listen.rsplit(":", 1)[-1] == "0":
            raise ConfigError("--via-refbox needs a fixed --refbox port (our base stations connect to it), not 0")
        if not -1 <= self.live <= 65535:
            raise ConfigError(f"--live port must be in 0..65535, got {self.live}")
        if not (math.isfinite(self.pace) and 0.0 <= self.pace <= 1000.0):
            raise ConfigError(f"--pace must be between 0 (unpaced) and 1000, got {self.pace}")
        if self.pace > 0 and (self.live < 0 or self.realtime):
            raise ConfigError("--pace applies to a lockstep match with --live only")
        self._validate_params()
        for ext in self.external:
            pid = ProcessId.parse(ext)
            if pid not in self.processes():
                raise ConfigError(f"--external {ext}: no such process in this match")

    def _validate_params(self) -> None:
        """The shape of `params`: teams a and b, names, finite scalar values. Whether the strategy declares
        a name, its type and range are checked where strategies are known (strategies/params.py `check`)."""
        for team, values in self.params.items():
            if team not in TEAMS or not isinstance(values, dict):
                raise ConfigError(f"params: {team!r} is no team; use params.a or params.b (name = value)")
            for name, value in values.items():
                if not isinstance(name, str) or not name.isidentifier():
                    raise ConfigError(f"params.{team}: {name!r} is no parameter name")
                if isinstance(value, float) and not math.isfinite(value):
                    raise ConfigError(f"params.{team}.{name} must be finite, got {value}")
                if not isinstance(value, bool | int | float | str):
                    raise ConfigError(f"params.{team}.{name} must be a number, true/false or a string, got {value!r}")


class ConfigError(ValueError):
    """A configuration or command-line value that cannot be used."""


class ProcessId(msgspec.Struct, frozen=True, order=True):
    """Who a process is: kind, and for team processes the team and robot number."""

    kind: str
    team: str = ""
    robot: int = -1

    def __str__(self) -> str:
        if self.kind == "robot":
            return f"robot/{self.team}/{self.robot}"
        if self.kind == "basestation":
            return f"basestation/{self.team}"
        return self.kind

    @property
    def short(self) -> str:
        """`a/1` for robots (the --external form), else the full name."""
        return f"{self.team}/{self.robot}" if self.kind == "robot" else str(self)

    @classmethod
    def parse(cls, text: str) -> ProcessId:
        """Accepts `robot/a/1`, `a/1`, `basestation/a`, `engine`, `referee`, `recorder`."""
        parts = text.strip().strip("/").split("/")
        try:
            if len(parts) == 2 and parts[0] in TEAMS:
                return cls("robot", parts[0], int(parts[1]))
            if parts[0] == "robot" and len(parts) == 3 and parts[1] in TEAMS:
                return cls("robot", parts[1], int(parts[2]))
            if parts[0] == "basestation" and len(parts) == 2 and parts[1] in TEAMS:
                return cls("basestation", parts[1])
            if len(parts) == 1 and parts[0] in ("engine", "referee", "recorder", "refbox", "viewer"):
                return cls(parts[0])
        except ValueError:
            pass
        raise ConfigError(
            f"bad process name {text!r}: use a/1 or robot/a/1, basestation/a, engine, referee, refbox, recorder or viewer"
        )
