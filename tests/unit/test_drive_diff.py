"""The engine's differential-drive model (sim/drive.py, model "diff"): paper 3 eq. 13 in the engine."""

from __future__ import annotations

import math

import pytest

from arena.config import EPUCK, ROBOTINO, MatchConfig, RobotParams
from arena.navigation import diffdrive
from arena.processes.engine import check_cmd
from arena.schemas.messages import Cmd
from arena.sim.drive import Drive
from arena.sim.physics import Physics

P = diffdrive.DiffDriveParams(wheel_radius=EPUCK.wheel_radius, axle_length=2 * EPUCK.wheel_base)


def body(vx: float = 0.0, vy: float = 0.0, omega: float = 0.0) -> Cmd:
    return Cmd(tick=0, vx=vx, vy=vy, omega=omega)


def wheels(w: list[float]) -> Cmd:
    return Cmd(tick=0, mode="wheels", wheels=w)


def test_the_matrices_are_paper_3_eq_13():
    d = Drive(EPUCK)
    assert d.wheels == 2 and not d.holonomic
    for v, omega in [(0.1, 0.0), (0.0, 2.0), (0.05, -1.5)]:
        assert d.wheel_speeds(v, 0.0, omega) == pytest.approx(list(diffdrive.wheel_speeds(v, omega, P)))
    wr, wl = 3.0, -1.0
    v, omega = diffdrive.body_velocity(wr, wl, P)
    assert d.body_twist([wr, wl]) == pytest.approx((v, 0.0, omega))


def test_omni_models_stay_holonomic():
    assert Drive(RobotParams()).holonomic and Drive(ROBOTINO).holonomic


def test_the_wheels_cannot_move_sideways():
    d = Drive(EPUCK)
    assert d.wheel_speeds(0.0, 0.3, 0.0) == [0.0, 0.0]
    vx, vy, w = d.twist(body(0.05, 0.08, 0.5))
    assert vy == 0.0
    assert (vx, w) == pytest.approx((0.05, 0.5))


def test_wheel_saturation_keeps_the_path_curvature():
    """Paper 3's law asks v = k_rho rho (1.5 m/s at the start): the motors scale it down, turning radius kept."""
    d = Drive(EPUCK)
    v, omega = 1.5, 2.0
    w = d.wheel_speeds(v, 0.0, omega)
    assert max(abs(x) for x in w) > EPUCK.max_wheel_speed
    vx, vy, wz = d.twist(wheels(w))
    assert max(abs(x) for x in d.wheel_speeds(vx, vy, wz)) == pytest.approx(EPUCK.max_wheel_speed)
    assert vx / wz == pytest.approx(v / omega)
    assert vx <= EPUCK.max_speed and abs(wz) <= EPUCK.max_omega


def test_the_engine_accepts_two_wheel_commands_for_a_diff_robot():
    assert check_cmd(wheels([1.0, 1.0]), Drive(EPUCK).wheels) is None
    assert check_cmd(wheels([1.0] * 3), Drive(EPUCK).wheels) == "3 wheel speeds (this robot has 2)"


def test_a_diff_robot_drives_along_its_heading_in_the_physics():
    cfg = MatchConfig(robots=1, robot=EPUCK)
    ph = Physics(cfg)
    ph.place_ball(-6.5, -4.6)
    ph.place_robot("b", 0, 5.0, -3.0, 0.0)
    heading = math.radians(30.0)
    ph.place_robot("a", 0, 0.0, 0.0, heading)
    full = EPUCK.max_wheel_speed
    ph.set_command("a", 0, wheels([full, full]))
    for _ in range(100):  # 2 s
        ph.step()
    x, y, theta = ph.robot_pose("a", 0)
    speed = full * EPUCK.wheel_radius  # [m/s] rim speed
    assert math.hypot(x, y) == pytest.approx(2.0 * speed, rel=0.05)
    assert math.atan2(y, x) == pytest.approx(heading, abs=1e-3)
    assert theta == pytest.approx(heading, abs=1e-6)
    ph.set_command("a", 0, wheels([full, -full]))  # turn on the spot, counter-clockwise
    for _ in range(10):
        ph.step()
    x2, y2, theta2 = ph.robot_pose("a", 0)
    assert theta2 > theta
    assert math.hypot(x2 - x, y2 - y) < 0.01
