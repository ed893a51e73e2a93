"""`arena bench nav`: the navigators against the experiments of their papers.

* **Paper 1** (Dewantara, Ariyadi and Oktavianto 2021, Section 3, Tables 3-6):
  the Robotino among two opponents, in three scenario families (static,
  crossing, pursuing), with the schemes of Table 3 (SFM k = 100 and 300, APF
  zeta = 100 and 300, F-SFM with two output-set schemes) plus MAPF. Each
  scheme runs `trials` trials that differ by seeded noise; reported per scheme:
  average iterations to the target, collision-free trials, % safe navigation,
  next to the paper's numbers.
* **Compute time**: the median wall time of one navigator call per method, of
  one whole iteration, and F-SFM's overhead over SFM (paper 1 Section 3.3:
  +9.05 %).
* **Paper 3** (Puriyanto et al., Section III-B, Table I): the E-puck in the
  SAROG and GNRON local minima with APF and MAPF: reached, path length,
  minimum clearance.

Everything is stepped in this process through the engine's own robot model:
`sim/physics/` (pymunk bodies driven through `sim/drive.py`'s
wheels, the same code a match runs) and `sim/sensors.py` for perception.
The robot is team a's robot 0; the obstacles are team b's robots, opponents of
the same model, driven by scripted commands. A collision is the engine's own
robot-robot contact event (FOUL_PUSHING with the pushing threshold at -inf, so
every contact counts).

Scenario definitions are data: `navbench.toml` next to this module, or a
user's file (`--scenarios FILE`). The parameters live there, not here.
Every random number comes from one numpy Generator per trial, seeded from
(seed, scenario, trial) and shared by every scheme (common random numbers), so
the same seed gives the same results; only the wall-clock timings differ.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import statistics
import time
import tomllib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import msgspec
import numpy as np

from arena.navigation import NAVIGATORS, PARAMS, diffdrive, pid
from arena.navigation.frames import field_to_robot, robot_to_field
from arena.runtime import config as runtime_config
from arena.runtime.config import ConfigError, MatchConfig, RobotParams, RulesParams, SensorParams, TimingParams
from arena.runtime.seeds import derive
from arena.schemas.messages import Cmd
from arena.sim.drive import Drive
from arena.sim.physics import Physics
from arena.sim.sensors import sense

BUILTIN = "navbench.toml"  # package data of arena.tools
METHODS = ("apf", "sfm", "f-sfm", "mapf")
ORDER = ("f-sfm", "sfm", "apf")  # paper 1's claim: safe rate F-SFM >= SFM >= APF
PAPER_SFM_MS = 32.34  # [ms] paper 1 Section 3.3, one iteration with fixed k
PAPER_FSFM_MS = 35.27  # [ms] the same with the FIS
PAPER_FIS_OVERHEAD = 9.05  # [%]
FSFM_BUDGET_US = 50.0  # [us] issue 7: median F-SFM step on this machine
PARK_Y = -4.6  # [m] spare robots and the ball wait in the run-off below the field
Clock = Callable[[], int]  # monotonic nanoseconds


class ScenarioError(ConfigError):
    """A scenario file that cannot be used; the CLI prints it as one line and exits 2."""


# ----------------------------------------------------------------- the file
class NoiseSpec(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    obstacle_start_sigma: float = 0.0  # [m]
    obstacle_speed_sigma: float = 0.0  # [m/s]
    sensor: bool = False  # perception through sim/sensors.py with SensorParams()


class ObstacleSpec(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    start: tuple[float, float]  # [m]
    velocity: tuple[float, float] = (0.0, 0.0)  # [m/s] constant, field frame
    pursue_speed: float = 0.0  # [m/s] > 0: drives towards the scenario's target at this speed
    stop_distance: float = 0.0  # [m] a pursuer stops this close to the target
    heading: float | None = None  # [rad] default: its direction of motion, else 0


class ReferenceRow(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    iterations: float  # paper's average iterations to the target
    free: int  # paper's collision-free trials


class SchemeSpec(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    name: str
    method: str
    label: str = ""
    params: dict[str, Any] = {}


class ScenarioSpec(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    name: str
    robot: str
    dt: float  # [s]
    substeps: int
    time_limit: float  # [s]
    goal_tolerance: float  # [m]
    start: tuple[float, float]  # [m]
    target: tuple[float, float]  # [m]
    obstacles: list[ObstacleSpec]
    controller: Literal["omni", "diff"] = "omni"
    robot_params: dict[str, Any] = {}  # overrides of the preset's RobotParams fields
    heading: float = 0.0  # [rad]
    title: str = ""
    paper: str = ""
    noise: NoiseSpec = NoiseSpec()
    schemes: list[str] | None = None  # default: every [[scheme]]
    reference: dict[str, ReferenceRow] = {}


class GainsSpec(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    k_rho: float
    k_alpha: float
    k_beta: float


class LocalMinimumSpec(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    name: str
    robot: str
    dt: float
    substeps: int
    time_limit: float
    goal_tolerance: float
    start: tuple[float, float]
    goal: tuple[float, float]
    obstacles: list[tuple[float, float]]
    gains: GainsSpec
    methods: dict[str, dict[str, Any]]
    robot_params: dict[str, Any] = {}  # overrides of the preset's RobotParams fields
    heading: float = 0.0
    title: str = ""
    reference: dict[str, float] = {}


class BenchFile(msgspec.Struct, forbid_unknown_fields=True):
    scheme: list[SchemeSpec] = []
    scenario: list[ScenarioSpec] = []
    local_minimum: list[LocalMinimumSpec] = []


# ----------------------------------------------------- resolved definitions
@dataclass(frozen=True)
class Scheme:
    name: str  # "#1"
    method: str  # a name in arena.navigation.NAVIGATORS
    label: str
    params: Any  # the navigator's frozen params dataclass


@dataclass(frozen=True)
class Scenario:
    spec: ScenarioSpec
    robot: RobotParams
    schemes: tuple[Scheme, ...]

    @property
    def name(self) -> str:
        return self.spec.name


@dataclass(frozen=True)
class LocalMinimum:
    spec: LocalMinimumSpec
    robot: RobotParams
    methods: tuple[tuple[str, Any], ...]  # (method, params)

    @property
    def name(self) -> str:
        return self.spec.name


@dataclass(frozen=True)
class BenchSpec:
    source: str
    scenarios: tuple[Scenario, ...]
    local_minima: tuple[LocalMinimum, ...]


def builtin_text() -> str:
    return resources.files("arena.tools").joinpath(BUILTIN).read_text(encoding="utf-8")


def load(path: str | Path | None = None) -> BenchSpec:
    """The benchmark definitions: the built-in file, or ``path`` completed by it.

    A user file's [defaults] keys override the built-in [defaults] one by one;
    its [[scheme]] tables, if it has any, replace the built-in schemes. Its
    [[scenario]] and [[local_minimum]] tables are the ones that run. Raises
    ScenarioError with a one-line reason.
    """
    builtin = _parse(builtin_text(), f"built-in {BUILTIN}")
    if path is None:
        return _resolve(builtin, f"built-in {BUILTIN}")
    name = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"--scenarios {name}: no such file") from None
    except IsADirectoryError:
        raise ScenarioError(f"--scenarios {name}: is a directory") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"--scenarios {name}: cannot read: {exc}") from None
    user = _parse(text, name)
    defaults = user.get("defaults", {})
    if not isinstance(defaults, dict):
        raise ScenarioError(f"{name}: [defaults] must be a table")
    user["defaults"] = _merge(builtin.get("defaults", {}), defaults)
    if "scheme" not in user:
        user["scheme"] = builtin.get("scheme", [])
    if not user.get("scenario") and not user.get("local_minimum"):
        raise ScenarioError(f"{name}: no [[scenario]] or [[local_minimum]] table")
    return _resolve(user, name)


def _parse(text: str, name: str) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{name}: not valid TOML: {exc}") from None


def _resolve(data: dict[str, Any], name: str) -> BenchSpec:
    data = dict(data)
    defaults = data.pop("defaults", {})
    if not isinstance(defaults, dict):
        raise ScenarioError(f"{name}: [defaults] must be a table")
    scenarios = data.get("scenario", [])
    if isinstance(scenarios, list):
        data["scenario"] = [_merge(defaults, s) if isinstance(s, dict) else s for s in scenarios]
    try:
        spec = msgspec.convert(data, BenchFile)
    except msgspec.ValidationError as exc:
        raise ScenarioError(f"{name}: {exc}") from None

    schemes: dict[str, Scheme] = {}
    for s in spec.scheme:
        if s.name in schemes:
            raise ScenarioError(f"{name}: scheme {s.name!r} is defined twice")
        if s.method not in NAVIGATORS:
            raise ScenarioError(
                f"{name}: scheme {s.name!r}: unknown method {s.method!r} (known: {', '.join(NAVIGATORS)})"
            )
        params = _override(PARAMS[s.method](), s.params, f"{name}: scheme {s.name!r} params")
        schemes[s.name] = Scheme(s.name, s.method, s.label or s.name, params)

    seen: set[str] = set()
    scenarios_out = []
    for sc in spec.scenario:
        where = f"{name}: scenario {sc.name!r}"
        _unique(sc.name, seen, where)
        robot = _robot(sc.robot, sc.robot_params, where)
        _check_timing(sc.dt, sc.substeps, sc.time_limit, sc.goal_tolerance, where)
        drive = Drive(robot)
        if (sc.controller == "omni") != drive.holonomic:
            raise ScenarioError(f"{where}: controller {sc.controller!r} does not fit robot model {robot.model!r}")
        if not 1 <= len(sc.obstacles) <= 6:
            raise ScenarioError(f"{where}: needs 1 to 6 obstacles, got {len(sc.obstacles)}")
        for p in (sc.start, sc.target, *(o.start for o in sc.obstacles)):
            _on_field(p, where)
        for o in sc.obstacles:
            if o.pursue_speed < 0 or o.stop_distance < 0:
                raise ScenarioError(f"{where}: pursue_speed and stop_distance must be >= 0")
            if o.pursue_speed > 0 and o.velocity != (0.0, 0.0):
                raise ScenarioError(f"{where}: an obstacle has both velocity and pursue_speed; choose one")
        if sc.noise.obstacle_start_sigma < 0 or sc.noise.obstacle_speed_sigma < 0:
            raise ScenarioError(f"{where}: noise sigmas must be >= 0")
        names = sc.schemes if sc.schemes is not None else list(schemes)
        missing = [n for n in [*names, *sc.reference] if n not in schemes]
        if missing:
            raise ScenarioError(f"{where}: unknown scheme {missing[0]!r} (defined: {', '.join(schemes) or 'none'})")
        if not names:
            raise ScenarioError(f"{where}: no schemes to run")
        scenarios_out.append(Scenario(sc, robot, tuple(schemes[n] for n in names)))

    minima = []
    for lm in spec.local_minimum:
        where = f"{name}: local_minimum {lm.name!r}"
        _unique(lm.name, seen, where)
        robot = _robot(lm.robot, lm.robot_params, where)
        _check_timing(lm.dt, lm.substeps, lm.time_limit, lm.goal_tolerance, where)
        if Drive(robot).holonomic:
            raise ScenarioError(f"{where}: robot {lm.robot!r} is not a differential drive (model {robot.model!r})")
        if not 1 <= len(lm.obstacles) <= 6:
            raise ScenarioError(f"{where}: needs 1 to 6 obstacles, got {len(lm.obstacles)}")
        for p in (lm.start, lm.goal, *lm.obstacles):
            _on_field(p, where)
        methods = []
        for m, over in lm.methods.items():
            if m not in NAVIGATORS:
                raise ScenarioError(f"{where}: unknown method {m!r} (known: {', '.join(NAVIGATORS)})")
            methods.append((m, _override(PARAMS[m](), over, f"{where}: methods.{m}")))
        if not methods:
            raise ScenarioError(f"{where}: no methods")
        minima.append(LocalMinimum(lm, robot, tuple(methods)))
    return BenchSpec(name, tuple(scenarios_out), tuple(minima))


def _merge(defaults: dict[str, Any], table: dict[str, Any]) -> dict[str, Any]:
    out = dict(defaults)
    for k, v in table.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _unique(name: str, seen: set[str], where: str) -> None:
    if name in seen:
        raise ScenarioError(f"{where}: the name is used twice")
    seen.add(name)


def _robot(preset: str, overrides: dict[str, Any], where: str) -> RobotParams:
    rp = getattr(runtime_config, preset, None)
    if not isinstance(rp, RobotParams):
        known = [k for k, v in vars(runtime_config).items() if isinstance(v, RobotParams)]
        raise ScenarioError(f"{where}: unknown robot {preset!r} (presets in arena.runtime.config: {', '.join(known)})")
    rp = _override(rp, overrides, f"{where}: robot_params")
    if not (rp.size > 0 and rp.mass > 0 and rp.max_accel > 0 and rp.max_alpha > 0 and rp.max_wheel_speed > 0):
        raise ScenarioError(f"{where}: robot size, mass, max_accel, max_alpha and max_wheel_speed must be > 0")
    try:
        Drive(rp)
    except ValueError as exc:
        raise ScenarioError(f"{where}: {exc}") from None
    return rp


def _check_timing(dt: float, substeps: int, time_limit: float, tol: float, where: str) -> None:
    if not (dt > 0 and substeps >= 1 and time_limit > 0 and tol > 0):
        raise ScenarioError(f"{where}: dt, time_limit and goal_tolerance must be > 0 and substeps >= 1")
    if time_limit / dt > 1_000_000:
        raise ScenarioError(f"{where}: time_limit / dt is over a million iterations")


def _on_field(p: tuple[float, float], where: str) -> None:
    f = runtime_config.FieldParams()
    if abs(p[0]) > f.length / 2 or abs(p[1]) > f.width / 2:
        raise ScenarioError(f"{where}: position {list(p)} is off the {f.length:g} m x {f.width:g} m field")


def _override(obj: Any, overrides: dict[str, Any], where: str) -> Any:
    """``obj`` (a frozen params dataclass) with ``overrides`` applied; nested tables go into nested dataclasses."""
    fields = {f.name: f for f in dataclasses.fields(obj) if f.init}
    changes: dict[str, Any] = {}
    for key, value in overrides.items():
        if key not in fields:
            raise ScenarioError(f"{where}: unknown parameter {key!r} (known: {', '.join(fields)})")
        current = getattr(obj, key)
        if dataclasses.is_dataclass(current):
            if not isinstance(value, dict):
                raise ScenarioError(f"{where}.{key}: expected a table")
            changes[key] = _override(current, value, f"{where}.{key}")
        elif isinstance(current, bool) or isinstance(value, bool):
            if not (isinstance(current, bool) and isinstance(value, bool)):
                raise ScenarioError(f"{where}.{key}: expected {type(current).__name__}, got {value!r}")
            changes[key] = value
        elif isinstance(current, float) and isinstance(value, (int, float)):
            changes[key] = float(value)
        elif type(value) is not type(current):
            raise ScenarioError(f"{where}.{key}: expected {type(current).__name__}, got {value!r}")
        else:
            changes[key] = value
    try:
        return dataclasses.replace(obj, **changes)
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"{where}: {exc}") from None


# --------------------------------------------------------------- the world
class World:
    """The engine's pymunk world with our robot (a/0), obstacles (b/0..) and everything else parked."""

    def __init__(self, robot: RobotParams, obstacles: int, dt: float, substeps: int) -> None:
        per_team = max(1, obstacles)
        self.cfg = MatchConfig(
            robots=per_team,
            robot=robot,
            timing=TimingParams(dt=dt, substeps=substeps),
            # every robot-robot contact between the teams is reported
            rules=RulesParams(push_speed=-math.inf),
        )
        self.physics = Physics(self.cfg)
        self.drive = Drive(robot)
        self.obstacles = obstacles
        f = self.cfg.field
        self.physics.place_ball(-f.length / 2 - 0.6, PARK_Y)
        spare = [(t, n) for t, n in self.physics.robot_ids if (t, n) != ("a", 0) and not (t == "b" and n < obstacles)]
        for i, (t, n) in enumerate(spare):
            self.physics.place_robot(t, n, f.length / 2 + 0.5 - 0.6 * i, PARK_Y, 0.0)

    def collisions(self, events: Iterable[Any]) -> int:
        return sum(1 for e in events if e.kind == "FOUL_PUSHING")


@dataclass
class Trial:
    """One run of one scheme in one scenario (or one local-minimum run)."""

    iterations: int  # navigator calls until the target was reached (or the limit)
    reached: bool
    collisions: int  # robot-obstacle contacts begun
    min_clearance: float  # [m] smallest centre distance minus the robot size (footprint gap)
    min_centre_distance: float  # [m]
    path_length: float  # [m] as the engine measures it (sum of substep displacements)
    robot_xy: np.ndarray  # (T, 2) [m] true positions, one per iteration
    obstacles_xy: np.ndarray  # (T, M, 2) [m]
    collision_xy: list[tuple[float, float]]  # [m] robot position at each contact
    nav_ns: list[int] = field(repr=False, default_factory=list)  # navigator call wall times
    iter_ns: list[int] = field(repr=False, default_factory=list)  # whole-iteration wall times

    def outcome(self) -> tuple:
        """Everything but the wall-clock timings: what determinism compares."""
        return (
            self.iterations,
            self.reached,
            self.collisions,
            self.min_clearance,
            self.path_length,
            self.robot_xy.tobytes(),
            self.obstacles_xy.tobytes(),
            tuple(self.collision_xy),
        )


def trial_rng(seed: int, scenario: str, trial: int) -> np.random.Generator:
    """The trial's one Generator: the same for every scheme of a scenario (common random numbers)."""
    return np.random.default_rng(derive(seed, "bench-nav", scenario, trial))


def run_trial(sc: Scenario, scheme: Scheme, trial: int, seed: int = 0, clock: Clock = time.perf_counter_ns) -> Trial:
    """One trial of ``scheme`` in paper-1 style scenario ``sc``; deterministic given (seed, scenario, trial)."""
    spec, rp = sc.spec, sc.robot
    rng = trial_rng(seed, spec.name, trial)
    world = World(rp, len(spec.obstacles), spec.dt, spec.substeps)
    ph, drive = world.physics, world.drive
    noise = spec.noise
    m = len(spec.obstacles)
    # Initial conditions first, a fixed number of draws, so that they never depend on the scheme.
    jitter = rng.standard_normal((m, 2)) * noise.obstacle_start_sigma
    speed_jitter = rng.standard_normal(m) * noise.obstacle_speed_sigma
    sensor_rng = np.random.default_rng(rng.integers(2**63))
    tx, ty = spec.target
    moves: list[tuple[float, float, float, float]] = []  # (vx, vy, pursue speed, stop distance)
    for i, o in enumerate(spec.obstacles):
        x0, y0 = o.start[0] + jitter[i, 0], o.start[1] + jitter[i, 1]
        vx, vy = o.velocity
        v = math.hypot(vx, vy)
        if v > 0:
            s = max(0.0, v + speed_jitter[i]) / v
            vx, vy = vx * s, vy * s
        pursue = max(0.0, o.pursue_speed + speed_jitter[i]) if o.pursue_speed > 0 else 0.0
        if o.heading is not None:
            th0 = o.heading
        elif pursue > 0:
            th0 = math.atan2(ty - y0, tx - x0)
        elif v > 0:
            th0 = math.atan2(vy, vx)
        else:
            th0 = 0.0
        ph.place_robot("b", i, x0, y0, th0)
        moves.append((vx, vy, pursue, o.stop_distance))
    ph.place_robot("a", 0, spec.start[0], spec.start[1], spec.heading)

    nav = NAVIGATORS[scheme.method]
    params = scheme.params
    pid_params = pid.PIDParams(max_output=rp.max_omega)
    pid_state = pid.PIDState()
    sensor_params = SensorParams()
    steps = int(round(spec.time_limit / spec.dt))
    size = rp.size
    robot_xy = np.empty((steps + 1, 2))
    obstacles_xy = np.empty((steps + 1, m, 2))
    nav_ns: list[int] = []
    iter_ns: list[int] = []
    hits: list[tuple[float, float]] = []
    min_d = math.inf
    reached = False
    it = 0
    for it in range(steps + 1):
        t0 = clock()
        states = ph.robot_states()
        me = next(s for s in states if s[0] == "a" and s[1] == 0)  # (team, n, x, y, theta, vx, vy, omega)
        x, y, theta = me[2], me[3], me[4]
        obs_true = [(s[2], s[3], s[4]) for s in states if s[0] == "b" and s[1] < m]
        robot_xy[it] = x, y
        for j, (ox, oy, _) in enumerate(obs_true):
            obstacles_xy[it, j] = ox, oy
            min_d = min(min_d, math.hypot(ox - x, oy - y))
        if math.hypot(tx - x, ty - y) <= spec.goal_tolerance:
            reached = True
            break
        if it == steps:
            break
        # perception: the engine's sensor model, or the truth
        if noise.sensor:
            z = sense(ph, "a", 0, it, sensor_rng, sensor_params, states)
            px, py, pth = z.pose.x, z.pose.y, z.pose.theta
            vel = robot_to_field(z.vx, z.vy, pth)
            seen = [(r.x, r.y) for r in z.robots if r.team == "b"]
        else:
            px, py, pth = x, y, theta
            vel = (me[5], me[6])
            seen = [(ox, oy) for ox, oy, _ in obs_true]
        # the opponents' scripted commands
        for j, (ox, oy, oth) in enumerate(obs_true):
            vx, vy, pursue, stop = moves[j]
            if pursue > 0:
                d = math.hypot(tx - ox, ty - oy)
                vx, vy = ((tx - ox) * pursue / d, (ty - oy) * pursue / d) if d > stop else (0.0, 0.0)
            bx, by = field_to_robot(vx, vy, oth)
            ph.set_command("b", j, Cmd(tick=it, vx=bx, vy=by))
        # our robot: navigator, heading PID (paper 1 eq. 15-16), wheels by inverse kinematics (eq. 2)
        n0 = clock()
        cvx, cvy = nav((px, py), vel, spec.target, seen, params)
        n1 = clock()
        beta = math.atan2(ty - py, tx - px)  # eq. 13
        omega, pid_state = pid.step(pid_state, beta, pth, pid_params)
        bx, by = field_to_robot(cvx, cvy, pth)
        ph.set_command("a", 0, Cmd(tick=it, mode="wheels", wheels=drive.wheel_speeds(bx, by, omega)))
        hits.extend((x, y) for _ in range(world.collisions(ph.step())))
        nav_ns.append(n1 - n0)
        iter_ns.append(clock() - t0)
    return Trial(
        iterations=it,
        reached=reached,
        collisions=len(hits),
        min_clearance=min_d - size,
        min_centre_distance=min_d,
        path_length=ph.distance[("a", 0)],
        robot_xy=robot_xy[: it + 1].copy(),
        obstacles_xy=obstacles_xy[: it + 1].copy(),
        collision_xy=hits,
        nav_ns=nav_ns,
        iter_ns=iter_ns,
    )


def run_local_minimum(lm: LocalMinimum, method: str, params: Any, clock: Clock = time.perf_counter_ns) -> Trial:
    """Paper 3 Section III-B: the differential-drive robot steered along the navigator's field.

    Per iteration: F from the navigator (its direction only), eq. 9 and 11
    (`diffdrive.track_direction`) give (v, omega), eq. 13 (the engine's
    Drive) gives the wheel speeds, and the engine moves the body. No noise:
    paper 3's runs are single and deterministic.
    """
    spec, rp = lm.spec, lm.robot
    world = World(rp, len(spec.obstacles), spec.dt, spec.substeps)
    ph, drive = world.physics, world.drive
    for j, (ox, oy) in enumerate(spec.obstacles):
        ph.place_robot("b", j, ox, oy, 0.0)
        ph.set_command("b", j, Cmd(tick=0))
    ph.place_robot("a", 0, spec.start[0], spec.start[1], spec.heading)
    gains = diffdrive.PolarGains(k_rho=spec.gains.k_rho, k_alpha=spec.gains.k_alpha, k_beta=spec.gains.k_beta)
    nav = NAVIGATORS[method]
    gx, gy = spec.goal
    obstacles = [tuple(o) for o in spec.obstacles]
    m = len(obstacles)
    steps = int(round(spec.time_limit / spec.dt))
    robot_xy = np.empty((steps + 1, 2))
    nav_ns: list[int] = []
    iter_ns: list[int] = []
    hits: list[tuple[float, float]] = []
    min_d = math.inf
    reached = False
    it = 0
    for it in range(steps + 1):
        t0 = clock()
        x, y, theta = ph.robot_pose("a", 0)
        vx, vy, _ = ph.robot_velocity("a", 0)
        robot_xy[it] = x, y
        for ox, oy in obstacles:
            min_d = min(min_d, math.hypot(ox - x, oy - y))
        rho = math.hypot(gx - x, gy - y)
        if rho < spec.goal_tolerance:
            reached = True
            break
        if it == steps:
            break
        n0 = clock()
        fx, fy = nav((x, y), (vx, vy), spec.goal, obstacles, params)
        n1 = clock()
        v, omega = diffdrive.track_direction(theta, fx, fy, rho, gains)  # eq. 9, 11
        ph.set_command("a", 0, Cmd(tick=it, mode="wheels", wheels=drive.wheel_speeds(v, 0.0, omega)))  # eq. 13
        hits.extend((x, y) for _ in range(world.collisions(ph.step())))
        nav_ns.append(n1 - n0)
        iter_ns.append(clock() - t0)
    return Trial(
        iterations=it,
        reached=reached,
        collisions=len(hits),
        min_clearance=min_d - rp.size,
        min_centre_distance=min_d,
        path_length=ph.distance[("a", 0)],
        robot_xy=robot_xy[: it + 1].copy(),
        obstacles_xy=np.broadcast_to(np.asarray(obstacles, dtype=float), (it + 1, m, 2)).copy(),
        collision_xy=hits,
        nav_ns=nav_ns,
        iter_ns=iter_ns,
    )


# -------------------------------------------------------------- the bench
@dataclass
class Report:
    seed: int
    trials: int
    source: str
    runs: dict[tuple[str, str], list[Trial]]  # (scenario, scheme) -> trials
    minima: dict[tuple[str, str], Trial]  # (env, method) -> run
    spec: BenchSpec

    def to_json(self) -> dict[str, Any]:
        return {
            "seed": self.seed,
            "trials": self.trials,
            "scenarios": self.source,
            "definitions": {
                "safe": "reached the target within the time limit without touching an obstacle",
                "collision_free": "never touched an obstacle (paper 1's 'free collision')",
                "avg_iterations": "mean navigator calls until the target was reached, over the trials that reached it",
                "us_per_iteration": "median wall time of one navigator call [us]",
                "iteration_us": "median wall time of one whole iteration: perception, navigator, engine tick [us]",
                "min_clearance_m": "smallest centre distance minus the robot size, the gap between two round "
                "footprints; the engine's robots are boxes, so corners can touch at up to 0.41 x size",
            },
            "results": results_rows(self),
            "methods": method_rows(self),
            "timing": timing(self),
            "mapf": minima_rows(self),
        }


def run_bench(
    spec: BenchSpec,
    trials: int = 10,
    seed: int = 0,
    only: Sequence[str] = (),
    progress: Callable[[str], None] | None = None,
    clock: Clock = time.perf_counter_ns,
) -> Report:
    """Every scheme of every scenario ``trials`` times, and every local-minimum run."""
    if trials < 1:
        raise ConfigError(f"--trials must be at least 1, got {trials}")
    spec = select(spec, only)
    runs: dict[tuple[str, str], list[Trial]] = {}
    for sc in spec.scenarios:
        for scheme in sc.schemes:
            out = runs[(sc.name, scheme.name)] = []
            for t in range(trials):
                out.append(run_trial(sc, scheme, t, seed, clock))
                if progress:
                    progress(f"{sc.name} {scheme.name}")
    mins: dict[tuple[str, str], Trial] = {}
    for lm in spec.local_minima:
        for method, params in lm.methods:
            mins[(lm.name, method)] = run_local_minimum(lm, method, params, clock)
            if progress:
                progress(f"{lm.name} {method}")
    return Report(seed, trials, spec.source, runs, mins, spec)


def select(spec: BenchSpec, only: Sequence[str] = ()) -> BenchSpec:
    """``spec`` cut down to the scenarios and local minima named in ``only`` (all when empty)."""
    if not only:
        return spec
    names = {s.name for s in spec.scenarios} | {lm.name for lm in spec.local_minima}
    unknown = [n for n in only if n not in names]
    if unknown:
        raise ConfigError(f"--only {unknown[0]}: no such scenario (have: {', '.join(sorted(names))})")
    return dataclasses.replace(
        spec,
        scenarios=tuple(s for s in spec.scenarios if s.name in only),
        local_minima=tuple(lm for lm in spec.local_minima if lm.name in only),
    )


def work_units(spec: BenchSpec, trials: int) -> int:
    """How many runs ``run_bench`` makes (for the progress bar)."""
    return sum(len(s.schemes) * trials for s in spec.scenarios) + sum(len(lm.methods) for lm in spec.local_minima)


def _median_us(ns: Iterable[int]) -> float | None:
    values = list(ns)
    return round(statistics.median(values) / 1000.0, 3) if values else None


def _avg_iterations(trials: list[Trial]) -> float | None:
    done = [t.iterations for t in trials if t.reached]
    return round(sum(done) / len(done), 1) if done else None


def _safe(t: Trial) -> bool:
    """Safe navigation: the target reached without touching an obstacle.

    Paper 1 uses "free collision" and "safe navigation" as synonyms, and all of
    its trials reach the target. Here a trial can also run out of time, so
    "safe" asks for both; the collision-free count alone is reported too.
    """
    return t.reached and t.collisions == 0


def _free(t: Trial) -> bool:
    return t.collisions == 0


def _ordered(rates: dict[str, float]) -> bool | None:
    """Paper 1's claim F-SFM >= SFM >= APF over the methods present (None with fewer than two)."""
    order = [m for m in ORDER if m in rates]
    return all(rates[a] >= rates[b] for a, b in zip(order, order[1:])) if len(order) > 1 else None


def results_rows(r: Report) -> list[dict[str, Any]]:
    rows = []
    for sc in r.spec.scenarios:
        for scheme in sc.schemes:
            ts = r.runs[(sc.name, scheme.name)]
            ref = sc.spec.reference.get(scheme.name)
            rows.append(
                {
                    "scenario": sc.name,
                    "method": scheme.method,
                    "scheme": scheme.name,
                    "label": scheme.label,
                    "trials": len(ts),
                    "reached": sum(t.reached for t in ts),
                    "collision_free": sum(_free(t) for t in ts),
                    "safe": sum(_safe(t) for t in ts),
                    "safe_rate": round(sum(_safe(t) for t in ts) / len(ts), 4),
                    "collision_free_rate": round(sum(_free(t) for t in ts) / len(ts), 4),
                    "avg_iterations": _avg_iterations(ts),
                    "us_per_iteration": _median_us(n for t in ts for n in t.nav_ns),
                    "iteration_us": _median_us(n for t in ts for n in t.iter_ns),
                    "min_clearance_m": round(min(t.min_clearance for t in ts), 4),
                    "paper_avg_iterations": ref.iterations if ref else None,
                    "paper_collision_free": ref.free if ref else None,
                    "paper_safe_rate": round(ref.free / 10, 4) if ref else None,
                }
            )
    return rows


def method_rows(r: Report) -> list[dict[str, Any]]:
    """Per scenario and method, both schemes pooled (as paper 1's "Avg. All" columns), and the ordering check."""
    out = []
    for sc in r.spec.scenarios:
        pooled: dict[str, list[Trial]] = {}
        paper: dict[str, list[int]] = {}
        for scheme in sc.schemes:
            pooled.setdefault(scheme.method, []).extend(r.runs[(sc.name, scheme.name)])
            ref = sc.spec.reference.get(scheme.name)
            if ref:
                paper.setdefault(scheme.method, []).append(ref.free)
        rates = {m: sum(_safe(t) for t in ts) / len(ts) for m, ts in pooled.items()}
        free = {m: sum(_free(t) for t in ts) / len(ts) for m, ts in pooled.items()}
        ordered, ordered_free = _ordered(rates), _ordered(free)
        for m in METHODS:
            if m not in pooled:
                continue
            ts = pooled[m]
            out.append(
                {
                    "scenario": sc.name,
                    "method": m,
                    "trials": len(ts),
                    "safe": sum(_safe(t) for t in ts),
                    "collision_free": sum(_free(t) for t in ts),
                    "reached": sum(t.reached for t in ts),
                    "safe_rate": round(rates[m], 4),
                    "collision_free_rate": round(free[m], 4),
                    "avg_iterations": _avg_iterations(ts),
                    "paper_safe_rate": round(sum(paper[m]) / (10 * len(paper[m])), 4) if m in paper else None,
                    "order_fsfm_sfm_apf_holds": ordered,
                    "order_holds_collision_free": ordered_free,
                }
            )
    return out


def timing(r: Report) -> dict[str, Any]:
    nav: dict[str, list[int]] = {}
    loop: dict[str, list[int]] = {}
    for sc in r.spec.scenarios:
        for scheme in sc.schemes:
            for t in r.runs[(sc.name, scheme.name)]:
                nav.setdefault(scheme.method, []).extend(t.nav_ns)
                loop.setdefault(scheme.method, []).extend(t.iter_ns)
    step_us = {m: _median_us(v) for m, v in nav.items()}
    iter_us = {m: _median_us(v) for m, v in loop.items()}
    out: dict[str, Any] = {"step_us_median": step_us, "iteration_us_median": iter_us}
    if step_us.get("sfm") and step_us.get("f-sfm"):
        out["fis_overhead_step_percent"] = round(100.0 * (step_us["f-sfm"] / step_us["sfm"] - 1.0), 1)
        out["fis_overhead_iteration_percent"] = round(100.0 * (iter_us["f-sfm"] / iter_us["sfm"] - 1.0), 1)
    if step_us.get("f-sfm") is not None:
        out["fsfm_within_budget"] = step_us["f-sfm"] <= FSFM_BUDGET_US
    out["paper"] = {"sfm_ms": PAPER_SFM_MS, "fsfm_ms": PAPER_FSFM_MS, "fis_overhead_percent": PAPER_FIS_OVERHEAD}
    return out


def minima_rows(r: Report) -> list[dict[str, Any]]:
    rows = []
    for lm in r.spec.local_minima:
        for method, _ in lm.methods:
            t = r.minima[(lm.name, method)]
            rows.append(
                {
                    "env": lm.name,
                    "method": method,
                    "reached": t.reached,
                    "path_length_m": round(t.path_length, 4),
                    "min_clearance_m": round(t.min_clearance, 4),
                    "min_centre_distance_m": round(t.min_centre_distance, 4),
                    "collisions": t.collisions,
                    "time_s": round(t.iterations * lm.spec.dt, 2),
                    "final_distance_to_goal_m": round(
                        math.hypot(lm.spec.goal[0] - t.robot_xy[-1, 0], lm.spec.goal[1] - t.robot_xy[-1, 1]), 4
                    ),
                    "paper_path_length_m": lm.spec.reference.get("path_length_m") if method == "mapf" else None,
                }
            )
    return rows


# ---------------------------------------------------------------- output
def print_report(r: Report, console: Any = None) -> None:
    from rich.console import Console
    from rich.table import Table

    if console is None:
        console = Console()
        if not console.is_terminal:
            console = Console(width=150)  # piped: wide enough for the tables
    rows = results_rows(r)
    methods = method_rows(r)
    for sc in r.spec.scenarios:
        ref = f", paper 1 {sc.spec.paper}" if sc.spec.paper else ""
        t = Table(title=f"{sc.name}: {sc.spec.title or ''} ({r.trials} trials{ref})", title_justify="left")
        for col, just in [
            ("scheme", "left"),
            ("method", "left"),
            ("avg iter", "right"),
            ("paper", "right"),
            ("reached", "right"),
            ("collision-free", "right"),
            ("paper", "right"),
            ("safe %", "right"),
            ("paper %", "right"),
            ("step us", "right"),
        ]:
            t.add_column(col, justify=just)
        for row in (x for x in rows if x["scenario"] == sc.name):
            pf = row["paper_collision_free"]
            t.add_row(
                row["scheme"],
                row["label"],
                _fmt(row["avg_iterations"], "{:.1f}"),
                _fmt(row["paper_avg_iterations"], "{:g}"),
                f"{row['reached']}/{row['trials']}",
                f"{row['collision_free']}/{row['trials']}",
                "-" if pf is None else f"{pf}/10",
                f"{100 * row['safe_rate']:.0f}",
                _fmt(row["paper_safe_rate"], "{:.0%}").rstrip("%"),
                _fmt(row["us_per_iteration"], "{:.1f}"),
            )
        t.add_section()
        for mrow in (x for x in methods if x["scenario"] == sc.name):
            n = mrow["trials"]
            t.add_row(
                "all",
                mrow["method"],
                _fmt(mrow["avg_iterations"], "{:.1f}"),
                "",
                f"{mrow['reached']}/{n}",
                f"{mrow['collision_free']}/{n}",
                "",
                f"{100 * mrow['safe_rate']:.0f}",
                _fmt(mrow["paper_safe_rate"], "{:.0%}").rstrip("%"),
                "",
            )
        mine = [x for x in methods if x["scenario"] == sc.name]
        if mine and mine[0]["order_fsfm_sfm_apf_holds"] is not None:
            word = {True: "holds", False: "does NOT hold"}
            t.caption = (
                f"F-SFM >= SFM >= APF: safe rate {word[mine[0]['order_fsfm_sfm_apf_holds']]}, "
                f"collision-free rate {word[mine[0]['order_holds_collision_free']]}"
            )
        console.print(t)

    tm = timing(r)
    t = Table(title="compute time per iteration (medians over every iteration of every trial)", title_justify="left")
    t.add_column("method")
    t.add_column("navigator step [us]", justify="right")
    t.add_column("whole iteration [us]", justify="right")
    for m in METHODS:
        if m in tm["step_us_median"]:
            t.add_row(m, _fmt(tm["step_us_median"][m], "{:.2f}"), _fmt(tm["iteration_us_median"][m], "{:.1f}"))
    if "fis_overhead_step_percent" in tm:
        t.add_section()
        t.add_row(
            "F-SFM over SFM",
            f"{tm['fis_overhead_step_percent']:+.1f} %",
            f"{tm['fis_overhead_iteration_percent']:+.1f} %",
        )
        t.add_row("paper 1 (whole iteration)", "", f"{PAPER_SFM_MS} -> {PAPER_FSFM_MS} ms, +{PAPER_FIS_OVERHEAD} %")
    if "fsfm_within_budget" in tm:
        t.caption = (
            f"F-SFM step median {'within' if tm['fsfm_within_budget'] else 'OVER'} the {FSFM_BUDGET_US:g} us budget"
        )
    console.print(t)

    if r.spec.local_minima:
        t = Table(title="paper 3 local minima, E-puck (differential drive), one run each", title_justify="left")
        for col in (
            "env",
            "method",
            "reached",
            "time [s]",
            "path [m]",
            "paper path [m]",
            "min clearance [m]",
            "min centre dist [m]",
            "final dist to goal [m]",
            "contacts",
        ):
            t.add_column(col, justify="left" if col in ("env", "method") else "right")
        for row in minima_rows(r):
            t.add_row(
                row["env"],
                row["method"],
                "yes" if row["reached"] else "no",
                f"{row['time_s']:.1f}",
                f"{row['path_length_m']:.3f}",
                _fmt(row["paper_path_length_m"], "{:.2f}"),
                f"{row['min_clearance_m']:.3f}",
                f"{row['min_centre_distance_m']:.3f}",
                f"{row['final_distance_to_goal_m']:.3f}",
                str(row["collisions"]),
            )
        console.print(t)


def _fmt(v: Any, pattern: str) -> str:
    return "-" if v is None else pattern.format(v)


# ----------------------------------------------------------------- plots
METHOD_COLOURS = {"apf": "tab:red", "sfm": "tab:orange", "f-sfm": "goldenrod", "mapf": "tab:purple"}


def write_plots(r: Report, out_dir: str | Path) -> list[Path]:
    """PNG trajectory plots in the manner of paper 1 Figs. 7-9 and paper 3 Figs. 7-8; returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for sc in r.spec.scenarios:
        first: dict[str, Scheme] = {}
        for scheme in sc.schemes:
            first.setdefault(scheme.method, scheme)
        panels = [first[m] for m in METHODS if m in first]
        fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 4.4), squeeze=False)
        half = sc.robot.size / 2
        for ax, scheme in zip(axes[0], panels):
            trials = r.runs[(sc.name, scheme.name)]
            for k, t in enumerate(trials):
                if k > 0:
                    ax.plot(t.robot_xy[:, 0], t.robot_xy[:, 1], color="gold", lw=0.8, alpha=0.45)
                    for j in range(t.obstacles_xy.shape[1]):
                        ax.plot(t.obstacles_xy[:, j, 0], t.obstacles_xy[:, j, 1], color="tab:blue", lw=0.5, alpha=0.2)
            t0 = trials[0]
            for j in range(t0.obstacles_xy.shape[1]):
                ax.plot(t0.obstacles_xy[:, j, 0], t0.obstacles_xy[:, j, 1], color="tab:blue", lw=1.6)
                ax.add_patch(Circle(tuple(t0.obstacles_xy[0, j]), half, fc="tab:blue", alpha=0.25, ec="tab:blue"))
                ax.add_patch(Circle(tuple(t0.obstacles_xy[-1, j]), half, fc="none", ec="tab:blue", ls="--"))
            ax.plot(t0.robot_xy[:, 0], t0.robot_xy[:, 1], color="darkgoldenrod", lw=2.0, label="robot, trial 1")
            ax.add_patch(Circle(tuple(t0.robot_xy[-1]), half, fc="none", ec="darkgoldenrod"))
            hits = [p for t in trials for p in t.collision_xy]
            if hits:
                ax.scatter(
                    [p[0] for p in hits], [p[1] for p in hits], marker="x", color="red", s=30, zorder=5, label="contact"
                )
            ax.plot(*sc.spec.start, "ko", ms=5)
            ax.plot(*sc.spec.target, marker="*", color="green", ms=14, ls="none", label="target")
            safe = sum(_safe(t) for t in trials)
            ax.set_title(f"{scheme.name} {scheme.label}\nsafe {safe}/{len(trials)}", fontsize=9)
            ax.set_aspect("equal")
            ax.set_xlim(sc.spec.start[0] - 0.7, sc.spec.target[0] + 1.0)
            ax.set_ylim(-2.3, 2.3)
            ax.grid(alpha=0.3)
            ax.set_xlabel("x [m]")
        axes[0][0].set_ylabel("y [m]")
        axes[0][0].legend(loc="lower left", fontsize=7)
        fig.suptitle(f"{sc.name}: {sc.spec.title} (yellow: robot, blue: obstacles; bold: trial 1)", fontsize=10)
        fig.tight_layout()
        path = out / f"nav_{_slug(sc.name)}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)

    if r.spec.local_minima:
        n = len(r.spec.local_minima)
        fig, axes = plt.subplots(1, n, figsize=(5.5 * n, 4.2), squeeze=False)
        for ax, lm in zip(axes[0], r.spec.local_minima):
            half = lm.robot.size / 2
            for ox, oy in lm.spec.obstacles:
                ax.add_patch(Circle((ox, oy), half, fc="tab:blue", alpha=0.5))
                for _method, params in lm.methods:
                    r_safe = getattr(params, "safe_distance", None)
                    if r_safe:
                        ax.add_patch(Circle((ox, oy), r_safe, fc="none", ec="grey", ls=":"))
                        break
            for method, _ in lm.methods:
                t = r.minima[(lm.name, method)]
                ax.plot(
                    t.robot_xy[:, 0],
                    t.robot_xy[:, 1],
                    color=METHOD_COLOURS.get(method, "k"),
                    lw=1.6,
                    label=f"{method}: {'reached' if t.reached else 'not reached'}, {t.path_length:.2f} m",
                )
            ax.plot(*lm.spec.start, "ko", ms=5)
            ax.plot(*lm.spec.goal, marker="*", color="green", ms=14, ls="none")
            ax.set_title(f"{lm.name}: {lm.spec.title}", fontsize=9)
            ax.set_aspect("equal")
            ax.grid(alpha=0.3)
            ax.set_xlabel("x [m]")
            ax.legend(fontsize=7, loc="upper left")
        axes[0][0].set_ylabel("y [m]")
        fig.suptitle("paper 3 local minima, E-puck (dotted: safe distance r of APF/MAPF)", fontsize=10)
        fig.tight_layout()
        path = out / "nav_local_minima.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)


# ------------------------------------------------------------------- CLI
def main(args: argparse.Namespace) -> int:
    """`arena bench nav`: bad input raises ConfigError (one line on stderr, exit 2, by arena/cli.py)."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    only = [s for part in (args.only or []) for s in part.split(",") if s]
    spec = select(load(args.scenarios), only)
    if args.trials < 1:
        raise ConfigError(f"--trials must be at least 1, got {args.trials}")
    if args.plots:
        plots = Path(args.plots)
        if plots.exists() and not plots.is_dir():
            raise ConfigError(f"--plots {args.plots}: exists and is not a directory")
    err = Console(stderr=True)
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=err,
        disable=not err.is_terminal,
        transient=True,
    ) as bar:
        task = bar.add_task("arena bench nav", total=work_units(spec, args.trials))

        def tick(what: str) -> None:
            bar.update(task, advance=1, description=f"arena bench nav: {what}")

        report = run_bench(spec, trials=args.trials, seed=args.seed, progress=tick)
    if args.plots:
        for p in write_plots(report, args.plots):
            err.print(f"wrote {p}")
    if args.json:
        print(json.dumps(report.to_json(), indent=2))
    else:
        print_report(report)
    return 0
