"""One trial of paper 1's experiments: the robot and its scripted opponents stepped through the engine's own physics and sensors."""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from arena.config import MatchConfig, RobotParams, RulesParams, SensorParams, TimingParams
from arena.experiments.navbench.spec import PARK_Y, Clock, Scenario, Scheme
from arena.navigation import NAVIGATORS, pid
from arena.navigation.frames import field_to_robot, robot_to_field
from arena.runtime.seeds import derive
from arena.schemas.messages import Cmd
from arena.sim.drive import Drive
from arena.sim.physics import Physics
from arena.sim.sensors import sense


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


def run_trial(sc: Scenario, scheme: Scheme, trial: int, seed: int = 0, clock: Clock = time.perf_counter_ns) -> Trial:  # noqa: PLR0915 - one trial, step by step as the papers run it
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
