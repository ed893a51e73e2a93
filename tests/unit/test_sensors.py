"""Unit tests of the robots' LIDAR-like sensor (sim/sensors.py)."""

from __future__ import annotations

import dataclasses
import math
import random
import statistics

import numpy as np
import pytest

from arena.config import MatchConfig
from arena.schemas.messages import BallSeen, Cmd
from arena.sim.physics import Physics
from arena.sim.sensors import sense

CFG = MatchConfig(robots=2)
P = CFG.sensor
N = 3000  # samples for the noise statistics


def make() -> Physics:
    """a0 at (0, 0) facing +x; the others parked far away in the -y run-off corner."""
    ph = Physics(CFG)
    ph.place_robot("a", 0, 0.0, 0.0, 0.0)
    ph.place_robot("a", 1, -6.5, -4.5, 0.0)
    ph.place_robot("b", 0, -5.5, -4.5, 0.0)
    ph.place_robot("b", 1, -4.5, -4.5, 0.0)
    ph.place_ball(2.0, 1.0)
    return ph


def test_pose_noise_statistics():
    ph = make()
    ph.place_robot("a", 0, 1.0, 2.0, 0.5)
    rng = np.random.default_rng(1)
    readings = [sense(ph, "a", 0, 0, rng, P).pose for _ in range(N)]
    for values, truth, sigma in (
        ([r.x for r in readings], 1.0, P.pose_sigma),
        ([r.y for r in readings], 2.0, P.pose_sigma),
        ([r.theta for r in readings], 0.5, P.heading_sigma),
    ):
        assert statistics.fmean(values) == pytest.approx(truth, abs=4 * sigma / math.sqrt(N))
        assert statistics.stdev(values) == pytest.approx(sigma, rel=0.1)


def test_heading_is_wrapped():
    ph = make()
    ph.place_robot("a", 0, 0.0, 0.0, math.pi - 0.001)
    rng = np.random.default_rng(2)
    thetas = [sense(ph, "a", 0, 0, rng, P).pose.theta for _ in range(500)]
    assert all(-math.pi < t <= math.pi for t in thetas)
    assert min(thetas) < -3.0 and max(thetas) > 3.0, "noise must wrap across +-pi"


@pytest.mark.parametrize("distance", [1.0, 4.0])
def test_ball_noise_grows_with_range(distance):
    ph = make()
    ph.place_ball(0.0, distance)
    rng = np.random.default_rng(3)
    balls = [sense(ph, "a", 0, 0, rng, P).ball for _ in range(N)]
    assert all(b.visible for b in balls)
    sigma = P.det_sigma + P.det_sigma_per_m * distance
    assert statistics.fmean(b.x for b in balls) == pytest.approx(0.0, abs=4 * sigma / math.sqrt(N))
    assert statistics.stdev(b.x for b in balls) == pytest.approx(sigma, rel=0.1)
    assert statistics.stdev(b.y for b in balls) == pytest.approx(sigma, rel=0.1)


def test_ball_range_limit():
    ph = make()
    rng = np.random.default_rng(4)
    ph.place_ball(P.ball_range - 0.05, 0.0)
    assert sense(ph, "a", 0, 0, rng, P).ball.visible
    ph.place_ball(P.ball_range + 0.05, 0.0)
    assert sense(ph, "a", 0, 0, rng, P).ball == BallSeen()


def test_robot_range_limit_team_colour_and_order():
    ph = make()
    ph.place_robot("b", 1, 0.0, P.robot_range - 0.05, 0.0)
    ph.place_robot("a", 1, 2.0, 0.0, 0.0)
    ph.place_robot("b", 0, -P.robot_range - 0.05, 0.0, 0.0)
    rng = np.random.default_rng(5)
    seen = sense(ph, "a", 0, 0, rng, P).robots
    assert [r.team for r in seen] == ["a", "b"], "sorted by range, self and far robots left out"
    assert (seen[0].x, seen[0].y) == pytest.approx((2.0, 0.0), abs=0.2)
    assert (seen[1].x, seen[1].y) == pytest.approx((0.0, P.robot_range), abs=0.3)
    assert not hasattr(seen[0], "robot")


def test_range_limits_follow_the_parameters():
    ph = make()
    p = dataclasses.replace(P, ball_range=1.0, robot_range=1.0)
    ph.place_robot("b", 0, 1.5, 0.0, 0.0)
    s = sense(ph, "a", 0, 0, np.random.default_rng(6), p)
    assert not s.ball.visible and s.robots == []


def test_odometry_is_in_the_body_frame():
    ph = make()
    ph.place_robot("a", 0, 0.0, 0.0, math.pi / 2)
    ph.set_command("a", 0, Cmd(tick=0, vx=1.0, vy=0.5, omega=0.2))
    for _ in range(100):
        ph.step()
    s = sense(ph, "a", 0, 100, np.random.default_rng(7), P)
    assert (s.vx, s.vy, s.omega) == pytest.approx((1.0, 0.5, 0.2), abs=0.02)
    assert s.tick == 100


def test_has_ball_comes_from_the_dribbler():
    ph = make()
    ph.place_ball(0.225 + 0.11 + 0.02, 0.0)
    rng = np.random.default_rng(8)
    assert not sense(ph, "a", 0, 0, rng, P).has_ball
    ph.set_command("a", 0, Cmd(tick=0, dribbler=True))
    ph.step()
    assert sense(ph, "a", 0, 1, rng, P).has_ball
    assert not sense(ph, "b", 0, 1, rng, P).has_ball


def test_seeded_reproducibility_and_no_global_random():
    ph = make()
    saved = random.getstate()
    try:
        random.seed(1)
        first = [sense(ph, "a", 0, k, np.random.default_rng(42), P) for k in range(3)]
        random.seed(2)
        again = [sense(ph, "a", 0, k, np.random.default_rng(42), P) for k in range(3)]
    finally:
        random.setstate(saved)
    assert first == again
    assert sense(ph, "a", 0, 0, np.random.default_rng(43), P) != first[0]


@pytest.mark.parametrize("block", [1, 7, 13, 4096])
def test_normal_stream_gives_the_generators_normals_in_order(block):
    """The engine draws sensor noise in blocks; the numbers must be the ones drawn one call at a time."""
    from arena.sim.sensors import NormalStream

    stream, ref = NormalStream(np.random.default_rng(3), block), np.random.default_rng(3)
    for n in [13, 13, 1, 0, 5000, 2, 4096, 13] * 3:
        assert stream.take(n) == ref.standard_normal(n).tolist()


def test_sense_is_the_same_with_a_normal_stream():
    from arena.sim.sensors import NormalStream

    ph = make()
    stream, gen = NormalStream(np.random.default_rng(9)), np.random.default_rng(9)
    for k in range(50):
        assert sense(ph, "a", 0, k, stream, P) == sense(ph, "a", 0, k, gen, P)


def test_sense_every_is_sense_for_each_robot_in_the_order_given():
    """The engine's per-tick call (the world read once) gives what `sense` gives robot by robot."""
    from arena.sim.sensors import NormalStream, sense_every

    ph = Physics(CFG.replace(robots=3))
    ph.kickoff_positions("b")
    ids = ph.robot_ids[::-1]  # not the physics' own order
    streams = {r: NormalStream(np.random.default_rng(i)) for i, r in enumerate(ids)}
    gens = {r: np.random.default_rng(i) for i, r in enumerate(ids)}
    rnd = random.Random(4)
    for k in range(200):
        if k % 10 == 0:
            for team, n in ids:
                ph.set_command(team, n, Cmd(tick=k, vx=rnd.uniform(-3, 3), vy=rnd.uniform(-3, 3), dribbler=True))
        ph.step()
        got = sense_every(ph, k, [(r, streams[r]) for r in ids], P)
        assert got == [sense(ph, team, n, k, gens[(team, n)], P) for team, n in ids]
    assert any(z.has_ball for z in got) or any(z.ball.visible for z in got)
