"""The scenario file's schema (`navbench.toml`, msgspec structs that reject unknown keys), its resolved form, and the bench's constants."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import msgspec

from arena.config import ConfigError, RobotParams

BUILTIN = "navbench.toml"  # package data of arena.experiments.navbench


METHODS = ("apf", "sfm", "f-sfm", "mapf")


ORDER = ("f-sfm", "sfm", "apf")  # paper 1's claim: safe rate F-SFM >= SFM >= APF


PAPER_SFM_MS = 32.34  # [ms] paper 1 Section 3.3, one iteration with fixed k


PAPER_FSFM_MS = 35.27  # [ms] the same with the FIS


PAPER_FIS_OVERHEAD = 9.05  # [%]


FSFM_BUDGET_US = 50.0  # [us] median F-SFM step on the development machine


PARK_Y = -4.6  # [m] spare robots and the ball wait in the run-off below the field


Clock = Callable[[], int]  # monotonic nanoseconds


class ScenarioError(ConfigError):
    """A scenario file that cannot be used; the CLI prints it as one line and exits 2."""


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
