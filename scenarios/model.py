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
from dataclasses import dataclass
from pathlib import Path

import msgspec
from msgspec import Struct

from arena.config import (
    DEFAULT_PERCEPTION_LATENCY,
    ConfigError,
    MatchConfig,
    ProcessId,
    RulesParams,
    ScenarioParams,
)
from arena.runtime.links import resolve
from arena.scenarios import files
from arena.scenarios.bounds import (
    MAX_RULE,
    MAX_SCORE,
    MAX_TIME_LIMIT,
    finite,
)
from arena.scenarios.draws import Draw
from arena.scenarios.draws import resolve as resolve_draws
from arena.scenarios.steps import DEFAULTS, condition, start_steps, step_of
from arena.schemas.messages import (
    Step,
    TeleportRobot,
)
from arena.schemas.vocabulary import TEAMS
from arena.strategies import registry

SUFFIX = ".scenario.toml"


class ScenarioError(ValueError):
    """A scenario file that cannot be used; the message is one line naming the file and the key."""


class Spec(Struct, kw_only=True, forbid_unknown_fields=True):
    """File tables: an unknown key is an error (a typo must not pass silently)."""


Num = float | Draw  # a number of `start` or `step`: given, or drawn per run (scenarios/draws.py)


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
    x: Num | None = None
    y: Num | None = None
    z: Num = 0.0
    vx: Num | None = None
    vy: Num | None = None
    vz: Num = 0.0
    by_force: bool = False
    safely: bool = False
    roll: bool = False


class RobotSpec(Spec):
    robot: str
    x: Num | None = None
    y: Num | None = None
    theta: Num | None = None
    vx: Num | None = None
    vy: Num | None = None
    omega: Num | None = None
    present: bool = True
    by_force: bool = False
    safely: bool = False


class RefereeSpec(Spec):
    command: str = "START"
    team: str = ""
    x: Num | None = None
    y: Num | None = None
    robot: str = ""


class ControlSpec(Spec):
    """SSL `RobotControl`: a robot driven with these body-frame velocities, kick and dribbler for `seconds`."""

    robot: str
    seconds: Num
    vx: Num = 0.0
    vy: Num = 0.0
    omega: Num = 0.0
    kick_speed: Num = 0.0
    kick_lob: bool = False
    dribbler: bool = False


class Start(Spec):
    stage: str = "FIRST_HALF"
    clock: Num = 0.0
    score: list[int | Draw] = msgspec.field(default_factory=lambda: [0, 0])
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
    overrides: dict[str, dict[str, Num]] = {}


class StepSpec(Spec):
    at: Num | None = None
    when: When | None = None
    link: LinkSpec | None = None
    kill: list[str] = []
    ball: BallSpec | None = None
    robots: list[RobotSpec] = []
    referee: RefereeSpec | None = None
    park: list[str] = []
    control: list[ControlSpec] = []


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
    speed: float = 0.0
    event: str = ""
    score: list[int] | None = None
    when: When | None = None


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
    ranged: bool = False  # some number of `start` or `step` is drawn per run (scenarios/draws.py)
    subs: tuple[Step, ...] = ()  # the substitution's steps (they depend on no draw)
    notes: tuple[str, ...] = ()  # what the user should know though nothing is wrong
    # match settings set over the file's, by dotted path as an experiment's factors (experiments/design.py)
    settings: tuple[tuple[str, object], ...] = ()

    @property
    def name(self) -> str:
        return self.spec.name

    def drawn(self, seed: int) -> dict[str, float | int]:
        """The numbers drawn for the run at `seed`, by their key in the file (`start.ball.x`); {} without ranges."""
        return resolve_draws(self.spec, seed)[1] if self.ranged else {}

    def params_at(self, seed: int) -> ScenarioParams:
        if not self.ranged:
            return self.params
        spec = resolve_draws(self.spec, seed)[0]
        return start_params(spec, self.dt, f"scenario[{self.index}]", subs=list(self.subs))

    def config(self, seed: int = 0, base: MatchConfig | None = None) -> MatchConfig:
        """The match every engine plays for this scenario: `base` (default values if None) with what
        plays, the time limit, the start and the steps; then the `settings`, if any."""
        p = self.spec.play
        base = base or MatchConfig()
        cfg = base.replace(
            seed=seed,
            home=self.home,
            away=self.away,
            robots=p.robots,
            link=p.link,
            half_time=p.half_time,
            external=tuple(p.external),
            timing=dataclasses.replace(base.timing, perception_latency=p.perception_latency),
            rules=dataclasses.replace(base.rules, **p.rules),
            scenario=self.params_at(seed),
        )
        if not self.settings:
            return cfg
        from arena.experiments.design import cell_config

        played = cell_config(cfg.replace(scenario=ScenarioParams()), dict(self.settings), f"{self.path}: {self.name}")
        return played.replace(scenario=cfg.scenario)

    def ticks(self, seconds: float) -> int:
        return int(round(seconds / self.dt))


def check_rules(p: Play, where: str) -> None:
    """The `play.rules` keys are RulesParams fields with usable values; counts become ints."""
    known = {f.name: f.type for f in dataclasses.fields(RulesParams)}
    for key, value in p.rules.items():
        if key not in known:
            raise ValueError(f"{where}.play.rules.{key}: not a rule parameter (docs/rules.md: {', '.join(known)})")
        if not (math.isfinite(value) and 0 <= value <= MAX_RULE) or (known[key] == "int" and value != int(value)):
            raise ValueError(
                f"{where}.play.rules.{key}: a number in [0, {MAX_RULE:g}] (a whole one for counts), got {value}"
            )
    p.rules = {k: int(v) if known[k] == "int" else float(v) for k, v in p.rules.items()}


def run_end(spec: ScenarioSpec, dt: float) -> tuple[float, str]:
    """The run's last moment [s] and why: `time_limit`, or the match's end when `start.clock` comes first."""
    clock = spec.start.clock if spec.start is not None else 0.0
    left = 2 * spec.play.half_time - clock  # type: ignore[operator]
    if round(left / dt) < round(spec.time_limit / dt):
        return left, f"the match ends {left:g} s in (start.clock {clock:g} s of 2 x {spec.play.half_time:g} s)"
    return spec.time_limit, f"time_limit {spec.time_limit:g} s"


def start_params(
    spec: ScenarioSpec, dt: float, where: str, base: Path = Path("."), subs: list[Step] | None = None
) -> ScenarioParams:
    """The engine's and the referee's share of `start` and `step` (time limit, clock, stage, steps).
    `subs`: the substitution's steps, if already read (they depend on no draw)."""
    p, st = spec.play, spec.start
    if st is not None:
        finite(st.clock, f"{where}.start.clock", 0.0, 2 * p.half_time, " s (the match's time)")  # type: ignore[arg-type]
    end, why = run_end(spec, dt)
    steps = [step_of(s, p.robots, dt, f"{where}.step[{i}]", end) for i, s in enumerate(spec.step)]
    ticks = int(round(spec.time_limit / dt))
    for i, step in enumerate(steps):
        if step.at > round(end / dt):
            raise ValueError(
                f"{where}.step[{i}].at: {spec.step[i].at:g} s is after the run's end ({why}): the step would never happen"
            )
    if subs is None:
        subs = substitution(spec, ticks, dt, where, base)[0]
    if st is None:
        return ScenarioParams(ticks=ticks, steps=tuple(steps + subs))
    if st.stage not in ("FIRST_HALF", "SECOND_HALF"):
        raise ValueError(f"{where}.start.stage: FIRST_HALF or SECOND_HALF, got {st.stage!r}")
    if len(st.score) != 2 or min(st.score) < 0 or max(st.score) > MAX_SCORE:
        raise ValueError(f"{where}.start.score: [goals of a, goals of b], each 0..{MAX_SCORE}, got {st.score}")
    if st.attack_dir_a not in (1, -1):
        raise ValueError(f"{where}.start.attack_dir_a: 1 or -1, got {st.attack_dir_a}")
    steps += subs
    return ScenarioParams(
        ticks=ticks,
        clock=int(round(st.clock / dt)),  # type: ignore[operator]
        stage=st.stage,
        score=(st.score[0], st.score[1]),
        attack_dir_a=st.attack_dir_a,
        steps=tuple(start_steps(st, p.robots, f"{where}.start") + steps),
    )


def substitution(spec: ScenarioSpec, ticks: int, dt: float, where: str, base: Path) -> tuple[list[Step], str]:
    """Replay with substitution: one team's robots follow their recorded poses, teleported every tick
    from the recording's tick `from / dt` on; the other team and the ball play live.
    Returns the steps and a note when the recording ends before the run does."""
    sub, robots = spec.play.substitute, spec.play.robots
    if sub is None:
        return [], ""
    from arena.recording.reader import RecordingError, load
    from arena.schemas.messages import World

    if sub.team not in TEAMS:
        raise ValueError(f"{where}.play.substitute.team: {sub.team!r} (a or b)")
    finite(sub.from_, f"{where}.play.substitute.from", 0.0, 1e6, " s")
    path = base / sub.recording  # relative to the scenario file
    try:
        files.regular_file(str(path), "recording")
        worlds = load(str(path), keep={"world"}).decoded("world", World)
    except ValueError as exc:
        raise ValueError(f"{where}.play.substitute.recording: {path}: {exc}") from None
    except (RecordingError, OSError) as exc:
        raise ValueError(f"{where}.play.substitute.recording: {exc}") from None
    first = int(round(sub.from_ / dt))
    by_tick = {w.tick - first: w for w in worlds if first <= w.tick <= first + ticks}
    if 0 not in by_tick:
        raise ValueError(f"{where}.play.substitute.from: the recording has no world frame at {sub.from_} s")
    last = max(by_tick)
    end = int(round(run_end(spec, dt)[0] / dt))
    note = ""
    if last < end:
        note = (
            f"{where}.play.substitute: the recording ends {last * dt:g} s into the run (of {end * dt:g} s); "
            f"from there team {sub.team} plays live"
        )
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
    return steps, note


def check_window(e: Expect, spec: ScenarioSpec, where: str) -> None:
    """The window `from` .. `within`/`until` lies inside the run and is not empty (with a `when` trigger
    the window counts from the trigger's tick, and the run's end cuts it)."""
    if e.within is not None and e.until is not None:
        raise ValueError(f"{where}: give `within` or `until`, not both (they are the same)")
    key, end = ("within", e.within) if e.within is not None else ("until", e.until)
    dt = DEFAULTS.timing.dt
    last, why = run_end(spec, dt)
    if e.when is None and end is not None and round(end / dt) > round(last / dt):
        raise ValueError(f"{where}.{key}: {end:g} s is after the run's end ({why})")
    if e.when is None and round(e.from_ / dt) > round(last / dt):
        raise ValueError(f"{where}.from: {e.from_:g} s is after the run's end ({why})")
    end = last if end is None else end
    if round(e.from_ / dt) > round(end / dt):
        raise ValueError(f"{where}.from: {e.from_:g} s is after the window's end ({end:g} s)")


def check_expectations(spec: ScenarioSpec, where: str) -> None:
    from arena.scenarios.expect import check_expect

    processes = {str(p) for p in DEFAULTS.replace(robots=spec.play.robots, external=()).processes()}
    names = set()
    for i, e in enumerate(spec.expect):
        check_expect(e, spec.play.robots, f"{where}.expect[{i}]")
        check_window(e, spec, f"{where}.expect[{i}]")
        if e.when is not None:
            condition(e.when, spec.play.robots, f"{where}.expect[{i}].when")
        if e.kind == "digest" and e.process not in processes:
            raise ValueError(
                f"{where}.expect[{i}].process: {e.process!r} is not a process of this match "
                f"({', '.join(sorted(processes))})"
            )
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


def check_play(spec: ScenarioSpec, where: str) -> tuple[str, str]:
    """What plays: the strategies' canonical names; the link preset and the match's numbers checked."""
    p = spec.play
    names = []
    for side in ("home", "away"):
        try:
            names.append(registry.resolve_name(getattr(p, side)))
        except ConfigError as exc:
            raise ValueError(f"{where}.play.{side}: {exc}") from None
    try:
        resolve(p.link, {})
    except ConfigError as exc:
        raise ValueError(f"{where}.play.link: {exc}") from None
    try:
        DEFAULTS.replace(
            robots=p.robots,
            half_time=p.half_time,
            timing=dataclasses.replace(DEFAULTS.timing, perception_latency=p.perception_latency),
            rules=dataclasses.replace(DEFAULTS.rules, **p.rules),
        )
    except ConfigError as exc:
        raise ValueError(play_error(str(exc), where)) from None
    for ext in p.external:
        ProcessId.parse(ext)
    return names[0], names[1]


def build(spec: ScenarioSpec, path: str, index: int) -> Scenario:
    """Validate one scenario table (raises ValueError naming the key below `scenario[i]`).

    A scenario with ranges is validated at both ends of every range (scenarios/draws.py)."""
    where = f"scenario[{index}]"
    dt = DEFAULTS.timing.dt
    if not (math.isfinite(spec.time_limit) and dt <= spec.time_limit <= MAX_TIME_LIMIT):
        raise ValueError(
            f"{where}.time_limit: a positive number of seconds, at most {MAX_TIME_LIMIT:g}, got {spec.time_limit}"
        )
    if not 0.0 <= spec.min_pass <= 1.0:
        raise ValueError(f"{where}.min_pass: a fraction in [0, 1], got {spec.min_pass}")
    check_rules(spec.play, where)
    home, away = check_play(spec, where)
    ends = [resolve_draws(spec, None, end, where)[0] for end in ("low", "high", "far")]
    ranged = ends[0] is not spec
    fixed = ends[0] if ranged else spec
    subs, note = substitution(fixed, int(round(spec.time_limit / dt)), dt, where, Path(path).parent)
    for variant in ends if ranged else [spec]:
        params = start_params(variant, dt, where, subs=subs)
        check_expectations(variant, where)
    sc = Scenario(
        spec=spec,
        path=path,
        index=index,
        params=params if not ranged else ScenarioParams(),
        dt=dt,
        home=home,
        away=away,
        ranged=ranged,
        subs=tuple(subs),
        notes=(note,) if note else (),
    )
    try:
        sc.config()
    except ConfigError as exc:
        raise ValueError(play_error(str(exc), where)) from None
    return sc


def load_all(path: str | Path) -> list[Scenario]:
    """Every scenario of one file, validated; raises ScenarioError (one line)."""
    path = str(path)
    try:
        data = files.parse(files.read_text(path))
        files.check_counts(data)
    except ValueError as exc:
        raise ScenarioError(f"{path}: {exc}") from None
    if files.misplaced(data):
        raise ScenarioError(f"{path}: {files.misplaced(data)}")
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
