"""Paper 3's local minima (SAROG, GNRON): the E-puck among static obstacles with APF and MAPF."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from arena.experiments.navbench.spec import Clock, LocalMinimum
from arena.experiments.navbench.trials import Trial, World
from arena.navigation import NAVIGATORS, diffdrive
from arena.schemas.messages import Cmd


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
