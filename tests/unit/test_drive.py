"""The engine's wheel model (sim/drive.py): both command forms through the same wheels."""

from __future__ import annotations

import math
import random

import pytest

from arena.config import ROBOTINO, RobotParams
from arena.navigation import omni3, omni4
from arena.processes.engine import check_cmd
from arena.schemas.messages import Cmd
from arena.sim.drive import Drive

IRIS = RobotParams()


def body(vx: float = 0.0, vy: float = 0.0, omega: float = 0.0) -> Cmd:
    return Cmd(tick=0, vx=vx, vy=vy, omega=omega)


def wheels(w: list[float]) -> Cmd:
    return Cmd(tick=0, mode="wheels", wheels=w)


@pytest.mark.parametrize("rp", [IRIS, ROBOTINO], ids=["omni4", "omni3"])
def test_wheel_speeds_give_back_the_twist(rp):
    d = Drive(rp)
    twist = (0.6, -0.4, 1.2)
    w = d.wheel_speeds(*twist)
    assert len(w) == d.wheels == (4 if rp.model == "omni4" else 3)
    assert d.twist(wheels(w)) == pytest.approx(twist)
    assert d.twist(body(*twist)) == twist


def test_the_matrices_are_the_papers():
    d4, d3 = Drive(IRIS), Drive(ROBOTINO)
    p4 = omni4.Omni4Params(wheel_distance=IRIS.wheel_base, wheel_radii=(IRIS.wheel_radius,) * 4)
    p3 = omni3.Omni3Params(wheel_radius=ROBOTINO.wheel_radius, wheel_distance=ROBOTINO.wheel_base)
    assert d4.wheel_speeds(0.3, 0.2, 0.5) == pytest.approx(list(omni4.inverse(0.3, 0.2, 0.5, p4)))
    assert d3.wheel_speeds(0.3, 0.2, 0.5) == pytest.approx(list(omni3.inverse(0.3, 0.2, 0.5, p3)))
    assert d3.body_twist([10.0, -5.0, 3.0]) == pytest.approx(tuple(omni3.forward([10.0, -5.0, 3.0], p3)))


@pytest.mark.parametrize("rp", [IRIS, ROBOTINO], ids=["omni4", "omni3"])
def test_saturation_is_the_same_for_both_command_forms(rp):
    d = Drive(rp)
    a, b, _ = d.inverse_rows[0]  # full speed along wheel 1's rolling direction, turning at full rate:
    n = math.hypot(a, b)  # within max_speed and max_omega, but over the wheel-speed limit
    twist = (rp.max_speed * a / n, rp.max_speed * b / n, rp.max_omega)
    w = d.wheel_speeds(*twist)
    assert max(abs(x) for x in w) > rp.max_wheel_speed
    from_body, from_wheels = d.twist(body(*twist)), d.twist(wheels(w))
    assert from_body == pytest.approx(from_wheels)
    assert max(abs(x) for x in d.wheel_speeds(*from_body)) == pytest.approx(rp.max_wheel_speed)
    scale = from_body[2] / twist[2]
    assert from_body == pytest.approx(tuple(scale * t for t in twist)), "direction and turn ratio kept"


def test_speed_and_turn_rate_caps_apply_after_the_wheels():
    d = Drive(IRIS)
    vx, vy, w = d.twist(body(8.0, 6.0, 0.0))
    assert math.hypot(vx, vy) == pytest.approx(IRIS.max_speed)
    assert math.atan2(vy, vx) == pytest.approx(math.atan2(6.0, 8.0))
    assert d.twist(body(omega=-20.0))[2] == pytest.approx(-IRIS.max_omega)
    spin = d.twist(wheels([50.0] * 4))  # all wheels alike: a pure turn, capped
    assert spin == pytest.approx((0.0, 0.0, IRIS.max_omega))


def test_wrong_wheel_count_gives_no_motion():
    assert Drive(IRIS).twist(wheels([10.0, 10.0, 10.0])) == (0.0, 0.0, 0.0)
    assert Drive(ROBOTINO).twist(wheels([10.0] * 4)) == (0.0, 0.0, 0.0)


def test_unknown_model_is_refused():
    with pytest.raises(ValueError, match="unknown robot model"):
        Drive(RobotParams(model="omni5"))


@pytest.mark.parametrize(
    ("cmd", "model", "problem"),
    [
        (wheels([1.0] * 4), IRIS, None),
        (wheels([1.0] * 3), ROBOTINO, None),
        (wheels([1.0] * 3), IRIS, "3 wheel speeds (this robot has 4)"),
        (wheels([1.0] * 4), ROBOTINO, "4 wheel speeds (this robot has 3)"),
        (wheels([1.0, float("inf"), 1.0, 1.0]), IRIS, "a wheel speed is not finite"),
        (body(vx=float("nan")), IRIS, "vx is not finite"),
    ],
    ids=["omni4", "omni3", "3-for-omni4", "4-for-omni3", "inf", "nan"],
)
def test_the_engine_rejects_commands_the_robot_model_cannot_mean(cmd, model, problem):
    assert check_cmd(cmd, Drive(model).wheels) == problem


@pytest.mark.parametrize("model", ["omni4", "omni3", "diff"])
def test_body_twist_is_bit_for_bit_the_saturated_inverse(model):
    """`twist` skips the wheel list; it must equal the written-out formula exactly."""
    from dataclasses import replace

    from arena.navigation.saturation import saturation_scale

    d = Drive(replace(IRIS, model=model))
    rng = random.Random(11)
    saturated = surely_not = 0
    for i in range(4000):
        top = 8 if i % 2 else 4  # around the caps, and within them
        c = body(rng.uniform(-top, top), rng.uniform(-top, top), rng.uniform(-30 / top, 30 / top))
        vx, vy, w = d._cap(c.vx, c.vy if d.holonomic else 0.0, c.omega)
        s = saturation_scale(d.wheel_speeds(vx, vy, w), d.max_wheel_speed)
        saturated += s < 1.0
        surely_not += math.hypot(vx, vy) * d._k_speed + abs(w) * d._k_omega <= d._unsaturated
        assert d.twist(c) == (vx * s, vy * s, w * s)
    assert saturated > 100 and surely_not > 100  # both branches ran, and the check wheel by wheel was skipped
    if d.holonomic:  # (a diff drive's bound is tight: every twist is either)
        assert 4000 - saturated - surely_not > 100  # and ran, where the bound could not tell


def test_a_limit_of_zero_is_still_an_error():
    from dataclasses import replace

    with pytest.raises(ValueError, match="max_wheel_speed"):
        Drive(replace(IRIS, max_wheel_speed=0.0)).twist(body(1.0))
