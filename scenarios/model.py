"""The scenario file (docs/scenarios.md): TOML read into typed, validated scenarios.

A file holds one or more `[[scenario]]` tables. Each says what plays (`play`),
how the match stands at tick 0 (`start`), what happens on the way (`step`:
teleports, referee commands, parked robots, at a simulated time or when a
condition first holds) and what must come true (`expect`, each with a name).
`Scenario.config(seed)` turns one into the `MatchConfig` every engine plays:
the start becomes steps at tick 0 (`MatchConfig.scenario`), so the engine and
the referee apply it like any other step (sim/director.py).

Every problem is a `ScenarioError` with one line: the file, the key
(`scenario[1].expect[0].within`) and what is wrong."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import msgspec
from msgspec import Struct

from arena.runtime.config import (
    DEFAULT_PERCEPTION_LATENCY,
    ConfigError,
    MatchConfig,
    ProcessId,
    RulesParams,
    ScenarioParams,
)
from arena.runtime.links import resolve
from arena.schemas.messages import (
    Condition,
    KillProcess,
    RefereeOverride,
    Region,
    SetLink,
    Step,
    TeleportBall,
    TeleportRobot,
)
from arena.schemas.vocabulary import REF_COMMANDS, TEAMS
from arena.strategies import registry

SUFFIX = ".scenario.toml"


class ScenarioError(ValueError):
    """A scenario file that cannot be used; the message is one line naming the file and the key."""


class Spec(Struct, kw_only=True, forbid_unknown_fields=True):
    """File tables: an unknown key is an error (a typo must not pass silently)."""


class Substitute(Spec):
    team: str
    recording: str
    from_: float = msgspec.field(default=0.0, name="from")


class Play(Spec):
    home: str = "basic-static"
    away: str = "basic-static"
    robots: int = 3
    link: str = "ideal"
    perception_latency: int = DEFAULT_PERCEPTION_LATENCY
    half_time: float = 300.0
    external: list[str] = []
    rules: dict[str, float] = {}
    substitute: Substitute | None = None


class BallSpec(Spec):
    x: float | None = None
    y: float | None = None
    z: float = 0.0
    vx: float | None = None
    vy: float | None = None
    vz: float = 0.0
    by_force: bool = False


class RobotSpec(Spec):
    robot: str
    x: float | None = None
    y: float | None = None
    theta: float | None = None
    vx: float | None = None
    vy: float | None = None
    omega: float | None = None
    present: bool = True
    by_force: bool = False


class RefereeSpec(Spec):
    command: str = "START"
    team: str = ""
    x: float | None = None
    y: float | None = None
    robot: str = ""


class Start(Spec):
    stage: str = "FIRST_HALF"
    clock: float = 0.0
    score: list[int] = msgspec.field(default_factory=lambda: [0, 0])
    attack_dir_a: int = 1
    referee: RefereeSpec = msgspec.field(default_factory=RefereeSpec)
    ball: BallSpec | None = None
    robots: list[RobotSpec] = []


class When(Spec):
    ball_in: list[float] | None = None
    robot: str = ""
    robot_in: list[float] | None = None
    command: str = ""
    possession: str = ""


class LinkSpec(Spec):
    preset: str
    overrides: dict[str, dict[str, float]] = {}


class StepSpec(Spec):
    at: float | None = None
    when: When | None = None
    link: LinkSpec | None = None
    kill: list[str] = []
    ball: BallSpec | None = None
    robots: list[RobotSpec] = []
    referee: RefereeSpec | None = None
    park: list[str] = []


class Expect(Spec):
    name: str
    kind: str
    team: str = ""
    robot: str = ""
    robots: list[str] = []
    region: list[float] | None = None
    command: str = ""
    within: float | None = None
    from_: float = msgspec.field(default=0.0, name="from")
    until: float | None = None
    distance: float = 0.0
    seconds: float = 0.0
    radius: float = 0.2
    process: str = ""
    digest: str = ""


class ScenarioSpec(Spec):
    name: str
    time_limit: float
    description: str = ""
    min_pass: float = 1.0
    measured: str = ""
    play: Play = msgspec.field(default_factory=Play)
    start: Start | None = None
    step: list[StepSpec] = []
    expect: list[Expect] = []


class FileSpec(Spec):
    scenario: list[ScenarioSpec]


def region(values: list[float] | None, where: str) -> Region | None:
    if values is None:
        return None
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{where}: a region is [x0, y0, x1, y1] in metres, got {values}")
    return Region(x0=values[0], y0=values[1], x1=values[2], y1=values[3])


def robot_id(text: str, robots: int, where: str) -> tuple[str, int]:
    parts = text.split("/")
    if len(parts) != 2 or parts[0] not in TEAMS or not parts[1].isdigit() or not 0 <= int(parts[1]) < robots:
        raise ValueError(f"{where}: {text!r} is not a robot of this match (a/0 .. b/{robots - 1})")
    return parts[0], int(parts[1])


def ball_action(b: BallSpec, where: str) -> TeleportBall:
    if b.z < 0:
        raise ValueError(f"{where}.z: the ball's height must be >= 0 m, got {b.z}")
    return TeleportBall(x=b.x, y=b.y, z=b.z, vx=b.vx, vy=b.vy, vz=b.vz, by_force=b.by_force)


def robot_action(r: RobotSpec, robots: int, where: str) -> TeleportRobot:
    team, n = robot_id(r.robot, robots, f"{where}.robot")
    return TeleportRobot(
        team=team,
        robot=n,
        x=r.x,
        y=r.y,
        orientation=r.theta,
        vx=r.vx,
        vy=r.vy,
        omega=r.omega,
        present=r.present,
        by_force=r.by_force,
    )


def referee_action(r: RefereeSpec, robots: int, where: str) -> RefereeOverride:
    if r.command not in REF_COMMANDS:
        raise ValueError(f"{where}.command: {r.command!r} is not an MSL RefBox command")
    if r.team not in ("a", "b", ""):
        raise ValueError(f"{where}.team: {r.team!r} (a, b or empty)")
    if r.command in ("FREEKICK", "THROWIN", "DROP_BALL") and (r.x is None or r.y is None):
        raise ValueError(f"{where}: {r.command} needs the ball spot x and y")
    n = robot_id(r.robot, robots, f"{where}.robot")[1] if r.robot else -1
    if (r.command in ("YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW", "REPAIR_OUT")) != (n >= 0):
        raise ValueError(f"{where}.robot: cards and REPAIR_OUT need a robot, other commands none")
    return RefereeOverride(command=r.command, team=r.team, x=r.x, y=r.y, robot=n)


@dataclass(frozen=True)
class Scenario:
    """One validated scenario: its file spec, where it came from, and the steps it makes."""

    spec: ScenarioSpec
    path: str
    index: int
    params: ScenarioParams
    dt: float
    home: str  # the strategies' canonical names (strategies/registry.py)
    away: str

    @property
    def name(self) -> str:
        return self.spec.name

    def config(self, seed: int = 0, base: MatchConfig | None = None) -> MatchConfig:
        """The match every engine plays for this scenario: `base` (default values if None) with what
        plays, the time limit, the start and the steps."""
        p = self.spec.play
        base = base or MatchConfig()
        return base.replace(
            seed=seed,
            home=self.home,
            away=self.away,
            robots=p.robots,
            link=p.link,
            half_time=p.half_time,
            external=tuple(p.external),
            timing=dataclasses.replace(base.timing, perception_latency=p.perception_latency),
            rules=dataclasses.replace(base.rules, **p.rules),
            scenario=self.params,
        )

    def ticks(self, seconds: float) -> int:
        return int(round(seconds / self.dt))


def start_steps(st: Start, robots: int, where: str) -> list[Step]:
    actions: list = []
    for i, r in enumerate(st.robots):
        actions.append(robot_action(r, robots, f"{where}.robots[{i}]"))
    if st.ball is not None:
        actions.append(ball_action(st.ball, f"{where}.ball"))
    actions.append(referee_action(st.referee, robots, f"{where}.referee"))
    return [Step(at=0, actions=actions)]


def step_actions(s: StepSpec, robots: int, where: str) -> list:
    """What a step does, in a fixed order: robots, parked robots, the ball, the referee, the links."""
    actions: list = [robot_action(r, robots, f"{where}.robots[{i}]") for i, r in enumerate(s.robots)]
    for i, name in enumerate(s.park):
        team, n = robot_id(name, robots, f"{where}.park[{i}]")
        actions.append(TeleportRobot(team=team, robot=n, present=False))
    if s.ball is not None:
        actions.append(ball_action(s.ball, f"{where}.ball"))
    if s.referee is not None:
        if s.at is None:
            raise ValueError(f"{where}.referee: a referee command needs `at`; the referee does not see `when`")
        actions.append(referee_action(s.referee, robots, f"{where}.referee"))
    if s.link is not None:
        if s.at is None:
            raise ValueError(f"{where}.link: a link change needs `at`; every receiver applies it at that tick")
        try:
            resolve(s.link.preset, s.link.overrides)
        except ConfigError as exc:
            raise ValueError(f"{where}.link: {exc}") from None
        actions.append(SetLink(preset=s.link.preset, overrides=s.link.overrides))
    actions += kill_actions(s, robots, where)
    if not actions:
        raise ValueError(f"{where}: a step does nothing (give ball, robots, referee, park, link or kill)")
    return actions


def kill_actions(s: StepSpec, robots: int, where: str) -> list:
    out = []
    for i, name in enumerate(s.kill):
        try:
            pid = ProcessId.parse(name)
        except ConfigError:
            pid = None
        if pid is None or pid.kind not in ("robot", "basestation") or pid.robot >= robots:
            raise ValueError(f"{where}.kill[{i}]: {name!r} is not a robot or base station of this match")
        if s.at is None:
            raise ValueError(f"{where}.kill: killing a process needs `at`; the process itself stops at that tick")
        out.append(KillProcess(process=str(pid)))
    return out


def condition(w: When, robots: int, where: str) -> Condition:
    if w.robot_in is not None:
        robot_id(w.robot, robots, f"{where}.robot")
    if w.command and w.command not in REF_COMMANDS:
        raise ValueError(f"{where}.command: {w.command!r} is not an MSL RefBox command")
    if w.possession not in ("a", "b", ""):
        raise ValueError(f"{where}.possession: {w.possession!r} (a or b)")
    cond = Condition(
        ball_in=region(w.ball_in, f"{where}.ball_in"),
        robot=w.robot,
        robot_in=region(w.robot_in, f"{where}.robot_in"),
        command=w.command,
        possession=w.possession,
    )
    if cond == Condition():
        raise ValueError(f"{where}: an empty condition")
    return cond


def step_of(s: StepSpec, robots: int, dt: float, where: str) -> Step:
    if (s.at is None) == (s.when is None):
        raise ValueError(f"{where}: give exactly one of `at` (seconds) and `when` (a condition)")
    actions = step_actions(s, robots, where)
    if s.at is not None:
        if not (math.isfinite(s.at) and s.at >= 0):
            raise ValueError(f"{where}.at: seconds >= 0, got {s.at}")
        return Step(at=int(round(s.at / dt)), actions=actions)
    assert s.when is not None
    return Step(at=-1, when=condition(s.when, robots, f"{where}.when"), actions=actions)


def check_rules(p: Play, where: str) -> None:
    """The `play.rules` keys are RulesParams fields with usable values; counts become ints."""
    known = {f.name: f.type for f in dataclasses.fields(RulesParams)}
    for key, value in p.rules.items():
        if key not in known:
            raise ValueError(f"{where}.play.rules.{key}: not a rule parameter (docs/rules.md: {', '.join(known)})")
        if not (math.isfinite(value) and value >= 0) or (known[key] == "int" and value != int(value)):
            raise ValueError(f"{where}.play.rules.{key}: a number >= 0 (a whole one for counts), got {value}")
    p.rules = {k: int(v) if known[k] == "int" else float(v) for k, v in p.rules.items()}


def start_params(spec: ScenarioSpec, dt: float, where: str, base: Path = Path(".")) -> ScenarioParams:
    """The engine's and the referee's share of `start` and `step` (time limit, clock, stage, steps)."""
    p, st = spec.play, spec.start
    steps = [step_of(s, p.robots, dt, f"{where}.step[{i}]") for i, s in enumerate(spec.step)]
    ticks = int(round(spec.time_limit / dt))
    for i, step in enumerate(steps):
        if step.at > ticks:
            raise ValueError(
                f"{where}.step[{i}].at: {spec.step[i].at:g} s is after the run's end "
                f"(time_limit {spec.time_limit:g} s): the step would never happen"
            )
    if st is None:
        return ScenarioParams(ticks=ticks, steps=tuple(steps + substitution(spec, ticks, dt, where, base)))
    if st.stage not in ("FIRST_HALF", "SECOND_HALF"):
        raise ValueError(f"{where}.start.stage: FIRST_HALF or SECOND_HALF, got {st.stage!r}")
    if len(st.score) != 2 or min(st.score) < 0:
        raise ValueError(f"{where}.start.score: [goals of a, goals of b], got {st.score}")
    if st.attack_dir_a not in (1, -1):
        raise ValueError(f"{where}.start.attack_dir_a: 1 or -1, got {st.attack_dir_a}")
    steps += substitution(spec, ticks, dt, where, base)
    return ScenarioParams(
        ticks=ticks,
        clock=int(round(st.clock / dt)),
        stage=st.stage,
        score=(st.score[0], st.score[1]),
        attack_dir_a=st.attack_dir_a,
        steps=tuple(start_steps(st, p.robots, f"{where}.start") + steps),
    )


def substitution(spec: ScenarioSpec, ticks: int, dt: float, where: str, base: Path) -> list[Step]:
    """Replay with substitution: one team's robots follow their recorded poses, teleported every tick
    from the recording's tick `from / dt` on; the other team and the ball play live."""
    sub, robots = spec.play.substitute, spec.play.robots
    if sub is None:
        return []
    from arena.recording.reader import RecordingError, load
    from arena.schemas.messages import World

    if sub.team not in TEAMS:
        raise ValueError(f"{where}.play.substitute.team: {sub.team!r} (a or b)")
    path = base / sub.recording  # relative to the scenario file
    try:
        worlds = load(str(path), keep={"world"}).decoded("world", World)
    except (RecordingError, OSError) as exc:
        raise ValueError(f"{where}.play.substitute.recording: {exc}") from None
    first = int(round(sub.from_ / dt))
    by_tick = {w.tick - first: w for w in worlds if first <= w.tick <= first + ticks}
    if 0 not in by_tick:
        raise ValueError(f"{where}.play.substitute.from: the recording has no world frame at {sub.from_} s")
    steps = []
    for k, w in sorted(by_tick.items()):
        acts = [
            TeleportRobot(
                team=r.team, robot=r.robot, x=r.x, y=r.y, orientation=r.theta, vx=r.vx, vy=r.vy, omega=r.omega
            )
            for r in w.robots
            if r.team == sub.team and r.robot < robots
        ]
        if acts:
            steps.append(Step(at=k, actions=acts))
    return steps


def check_window(e: Expect, time_limit: float, where: str) -> None:
    """The window `from` .. `within`/`until` lies inside the run and is not empty."""
    if e.within is not None and e.until is not None:
        raise ValueError(f"{where}: give `within` or `until`, not both (they are the same)")
    key, end = ("within", e.within) if e.within is not None else ("until", e.until)
    dt = MatchConfig().timing.dt
    if end is not None and round(end / dt) > round(time_limit / dt):
        raise ValueError(f"{where}.{key}: {end:g} s is after the run's end (time_limit {time_limit:g} s)")
    end = time_limit if end is None else end
    if round(e.from_ / dt) > round(end / dt):
        raise ValueError(f"{where}.from: {e.from_:g} s is after the window's end ({end:g} s)")


def check_expectations(spec: ScenarioSpec, where: str) -> None:
    from arena.scenarios.expect import check_expect

    names = set()
    for i, e in enumerate(spec.expect):
        check_expect(e, spec.play.robots, f"{where}.expect[{i}]")
        check_window(e, spec.time_limit, f"{where}.expect[{i}]")
        if e.name in names:
            raise ValueError(f"{where}.expect[{i}].name: {e.name!r} is used twice")
        names.add(e.name)


# MatchConfig names its command-line flags; a scenario file has these keys in `play`.
PLAY_KEYS = {"--robots": "robots", "--half-time": "half_time", "--perception-latency": "perception_latency"}


def play_error(message: str, where: str) -> str:
    """A MatchConfig error about `play`, naming the file's key rather than `arena match`'s flag."""
    for flag, key in PLAY_KEYS.items():
        if message.startswith(flag + " "):
            return f"{where}.play.{key}: {message[len(flag) + 1 :]}"
    return f"{where}.play: {message}"


def build(spec: ScenarioSpec, path: str, index: int) -> Scenario:
    """Validate one scenario table (raises ValueError naming the key below `scenario[i]`)."""
    where = f"scenario[{index}]"
    dt = MatchConfig().timing.dt
    p = spec.play
    if not (math.isfinite(spec.time_limit) and spec.time_limit > 0):
        raise ValueError(f"{where}.time_limit: a positive number of seconds, got {spec.time_limit}")
    if not 0.0 <= spec.min_pass <= 1.0:
        raise ValueError(f"{where}.min_pass: a fraction in [0, 1], got {spec.min_pass}")
    check_rules(p, where)
    params = start_params(spec, dt, where, Path(path).parent)
    check_expectations(spec, where)
    names = []
    for side in ("home", "away"):
        try:
            names.append(registry.resolve_name(getattr(p, side)))
        except ConfigError as exc:
            raise ValueError(f"{where}.play.{side}: {exc}") from None
    sc = Scenario(spec=spec, path=path, index=index, params=params, dt=dt, home=names[0], away=names[1])
    try:
        resolve(p.link, {})
    except ConfigError as exc:
        raise ValueError(f"{where}.play.link: {exc}") from None
    try:
        sc.config()
    except ConfigError as exc:
        raise ValueError(play_error(str(exc), where)) from None
    for ext in p.external:
        ProcessId.parse(ext)
    return sc


def load_all(path: str | Path) -> list[Scenario]:
    """Every scenario of one file, validated; raises ScenarioError (one line)."""
    path = str(path)
    try:
        data = tomllib.loads(Path(path).read_text())
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read it: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not TOML: {exc}") from None
    try:
        spec = msgspec.convert(data, FileSpec)
    except msgspec.ValidationError as exc:
        text = str(exc)
        if " - at `$" in text:
            msg, _, key = text.rpartition(" - at `$")
            key = key.rstrip("`").lstrip(".")
            raise ScenarioError(f"{path}: {key}: {msg[0].lower() + msg[1:]}") from None
        raise ScenarioError(f"{path}: {text[0].lower() + text[1:]}") from None
    out: list[Scenario] = []
    for i, s in enumerate(spec.scenario):
        try:
            out.append(build(s, path, i))
        except (ValueError, ConfigError) as exc:
            raise ScenarioError(f"{path}: {exc}") from None
        twin = next((sc for sc in out[:-1] if sc.name == s.name), None)
        if twin is not None:  # --name, the pytest id and the verdicts tell scenarios apart by name
            raise ScenarioError(f"{path}: scenario[{i}].name: {s.name!r} is already scenario[{twin.index}]'s")
    return out


def load(path: str | Path, name: str = "") -> Scenario:
    """One scenario: the file's only one, or the one called `name`."""
    scs = load_all(path)
    if name:
        for sc in scs:
            if sc.name == name:
                return sc
        raise ScenarioError(f"{path}: no scenario named {name!r} (it has {', '.join(s.name for s in scs)})")
    if len(scs) != 1:
        raise ScenarioError(f"{path}: {len(scs)} scenarios; name the one you want")
    return scs[0]


def discover(target: str | Path) -> list[Path]:
    """The scenario files of `target`: the file itself, or every *.scenario.toml under a directory."""
    p = Path(target)
    if p.is_dir():
        return sorted(p.rglob(f"*{SUFFIX}"))
    if not p.exists():
        raise ScenarioError(f"{p}: no such file or directory")
    return [p]
