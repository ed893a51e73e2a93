"""Unit tests for arena.navigation: worked examples of each paper equation, the
local-minimum cases of paper 3, and a conformance suite run on every
registered navigator.

Papers: 1 = Dewantara et al. 2021 (SFM, F-SFM, Robotino, heading PID);
2 = IRIS strategy and simulator (4-wheel omni); 3 = Puriyanto et al. (APF, MAPF,
differential drive).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.navigation import NAVIGATORS, PARAMS, apf, diffdrive, fsfm, get, mapf, omni3, omni4, pid, sfm
from arena.navigation.frames import field_to_robot, robot_to_field, wrap_angle
from arena.navigation.saturation import saturate, saturation_scale

# ---------------------------------------------------------------- helpers

EPUCK_MAX_WHEEL = 6.28  # [rad/s] E-puck motor limit, paper 3's robot
SIM_DT = 0.02  # [s] integration step of the closed-loop tests


def run_point_mass(step, params, start, goal, obstacles, steps, dt=SIM_DT, tol=0.01):
    """Integrate pos += step(...) * dt; return (final pos, min obstacle distance, step reached or None)."""
    q = [float(start[0]), float(start[1])]
    v = (0.0, 0.0)
    min_d = math.inf
    for i in range(steps):
        v = step(q, v, goal, obstacles, params)
        q[0] += v[0] * dt
        q[1] += v[1] * dt
        min_d = min([min_d] + [math.dist(q, o) for o in obstacles])
        if math.dist(q, goal) < tol:
            return q, min_d, i
    return q, min_d, None


def run_diffdrive(module, params, obstacle, goal, steps, start=(0.0, 0.0, 0.0), dt=SIM_DT, tol=0.01):
    """Paper 3's loop (Fig. 5): field force -> eq. 9/11 -> eq. 13 wheels, saturated -> eq. 8.

    Returns (final pose, min obstacle distance, step reached or None).
    """
    x, y, th = start
    dd, gains = diffdrive.DiffDriveParams(), diffdrive.PolarGains()
    min_d = math.inf
    for i in range(steps):
        rho = math.dist((x, y), goal)
        if rho < tol:
            return (x, y, th), min_d, i
        fx, fy = module.force((x, y), goal, [obstacle], params)
        v, w = diffdrive.track_direction(th, fx, fy, rho, gains)
        wr, wl = saturate(diffdrive.wheel_speeds(v, w, dd), EPUCK_MAX_WHEEL)
        v, w = diffdrive.body_velocity(float(wr), float(wl), dd)
        x, y, th = diffdrive.unicycle_step(x, y, th, v, w, dt)
        min_d = min(min_d, math.dist((x, y), obstacle))
    return (x, y, th), min_d, None


# ---------------------------------------------------------------- frames


@pytest.mark.parametrize(
    ("angle", "want"),
    [
        (0.0, 0.0),
        (math.pi, math.pi),
        (-math.pi, math.pi),
        (3 * math.pi, math.pi),
        (2 * math.pi + 0.1, 0.1),
        (-0.1, -0.1),
    ],
)
def test_wrap_angle_to_half_open_interval(angle, want):
    assert wrap_angle(angle) == pytest.approx(want)


def test_frame_rotation_round_trip():
    vx, vy = field_to_robot(1.0, 0.0, math.pi / 2)  # field +x seen by a robot facing +y
    assert (vx, vy) == pytest.approx((0.0, -1.0))
    assert robot_to_field(vx, vy, math.pi / 2) == pytest.approx((1.0, 0.0))


# ---------------------------------------------------------------- APF, paper 3 eq. 2-3


def test_apf_attractive_potential_and_force_eq2():
    p = apf.APFParams(k_a=1.0)
    pos, goal = (0.0, 0.0), (3.0, 4.0)
    assert apf.attractive_potential(pos, goal, p) == pytest.approx(0.5 * 1.0 * 5.0**2)  # 1/2 k_a D_rg^2
    assert apf.force(pos, goal, [], p) == pytest.approx((3.0, 4.0))  # -k_a (q - q_g)
    # the navigator clips to max_speed (2 m/s) along the same direction
    assert apf.step(pos, (0.0, 0.0), goal, [], p) == pytest.approx((1.2, 1.6))


def test_apf_repulsive_eq3_worked_example():
    p = apf.APFParams(k_a=0.0, k_r=50.0, safe_distance=0.3)
    pos, obstacle = (0.0, 0.0), (0.2, 0.0)
    d = 0.2
    f = 1 / d - 1 / 0.3  # 5 - 3.333.. = 1.666..
    assert apf.repulsive_potential(pos, obstacle, p) == pytest.approx(0.5 * 50.0 * f**2)  # 69.44
    # -grad: k_r (1/D - 1/r) / D^2 along (q - q_o) / D, i.e. -x here
    assert apf.force(pos, pos, [obstacle], p) == pytest.approx((-50.0 * f / d**2, 0.0))  # (-2083.3, 0)


def test_apf_no_repulsion_outside_safe_distance():
    p = apf.APFParams()
    assert apf.repulsive_potential((0.0, 0.0), (0.31, 0.0), p) == 0.0
    assert apf.force((0.0, 0.0), (1.0, 0.0), [(0.0, 0.31)], p) == pytest.approx((1.0, 0.0))


def _numeric_gradient(fn, q, h=1e-6):
    return (
        (fn((q[0] + h, q[1])) - fn((q[0] - h, q[1]))) / (2 * h),
        (fn((q[0], q[1] + h)) - fn((q[0], q[1] - h))) / (2 * h),
    )


@pytest.mark.parametrize("q", [(0.1, 0.05), (-0.15, 0.2), (0.0, -0.25), (0.12, 0.12)])
def test_apf_force_is_minus_gradient_of_potential(q):
    goal, obstacles = (1.5, 0.3), [(0.05, 0.0), (0.2, 0.1)]
    gx, gy = _numeric_gradient(lambda p: apf.potential(p, goal, obstacles), q)
    assert apf.force(q, goal, obstacles) == pytest.approx((-gx, -gy), rel=1e-5)


# ---------------------------------------------------------------- MAPF, paper 3 eq. 4-7


def test_mapf_eq6_eq7_worked_example():
    k_a, k_r, r, n = 1.0, 50.0, 0.3, 2.0
    p = mapf.MAPFParams(k_a=k_a, k_r=k_r, safe_distance=r, n=n)
    x, y = 0.0, 0.0
    xo, yo = 0.2, 0.1
    xg, yg = 1.5, 0.5
    d_or = math.hypot(xo - x, yo - y)
    d_rg = math.hypot(x - xg, y - yg)
    f = 1 / d_or - 1 / r
    fx = -k_a * (x - xg) - k_r * f * (xo - x) * d_rg**n / d_or**3 - 0.5 * k_r * n * f**2 * (x - xg) * d_rg ** (n - 2)
    fy = -k_a * (y - yg) - k_r * f * (yo - y) * d_rg**n / d_or**3 - 0.5 * k_r * n * f**2 * (y - yg) * d_rg ** (n - 2)
    assert mapf.force((x, y), (xg, yg), [(xo, yo)], p) == pytest.approx((fx, fy))
    assert mapf.repulsive_potential((x, y), (xg, yg), (xo, yo), p) == pytest.approx(0.5 * k_r * f**2 * d_rg**n)


def test_mapf_with_n_zero_is_apf():
    q, goal, obstacles = (0.1, -0.05), (1.5, 0.0), [(0.3, 0.0), (0.0, 0.2)]
    got = mapf.force(q, goal, obstacles, mapf.MAPFParams(n=0.0))
    assert got == pytest.approx(apf.force(q, goal, obstacles, apf.APFParams()))


@pytest.mark.parametrize("n", [1.0, 2.0, 5.0])
def test_mapf_force_is_minus_gradient_of_eq5(n):
    p = mapf.MAPFParams(n=n)
    q, goal, obstacles = (0.1, 0.05), (0.4, 0.3), [(0.05, -0.1), (0.3, 0.2)]
    gx, gy = _numeric_gradient(lambda s: mapf.potential(s, goal, obstacles, p), q)
    assert mapf.force(q, goal, obstacles, p) == pytest.approx((-gx, -gy), rel=1e-5)


def test_gnron_apf_stalls_short_of_goal_mapf_reaches_it():
    # Paper 3 environment 2: obstacle (1.3, 0) within r = 0.3 of the goal (1.5, 0). A point
    # mass coming from the side: APF settles where the repulsion balances the attraction,
    # on the r circle about 0.1 m from the goal; MAPF (n = 5, Table I) makes the goal the minimum.
    goal, obstacles, start = (1.5, 0.0), [(1.3, 0.0)], (1.5, 1.0)
    dt = 0.005  # [s] small enough that the point mass settles instead of chattering on the r circle
    q_apf, _, reached = run_point_mass(apf.step, apf.APFParams(), start, goal, obstacles, steps=2000, dt=dt)
    assert reached is None
    assert 0.05 < math.dist(q_apf, goal) < 0.15
    assert math.dist(q_apf, obstacles[0]) == pytest.approx(0.3, abs=0.01)
    _, min_d, reached = run_point_mass(mapf.step, mapf.ENVIRONMENT_2, start, goal, obstacles, steps=2000, dt=dt)
    assert reached is not None
    assert min_d > 0.15


@pytest.mark.parametrize(
    ("name", "module", "params"),
    [("apf", apf, apf.APFParams()), ("mapf", mapf, mapf.ENVIRONMENT_1)],
    ids=["apf", "mapf"],
)
def test_sarog_exact_alignment_is_an_equilibrium_for_a_point_mass(name, module, params):
    # Paper 3 environment 1 (robot (0,0), obstacle (0.9,0), goal (1.5,0)). On the line the
    # field has no lateral component for APF and MAPF alike, so gradient descent stops
    # in front of the obstacle: the point is a saddle of U_t and neither field leaves it.
    q, _, reached = run_point_mass(module.step, params, (0.0, 0.0), (1.5, 0.0), [(0.9, 0.0)], steps=500)
    assert reached is None, name
    assert q[1] == 0.0
    assert 0.55 < q[0] < 0.62  # about r = 0.3 before the obstacle


@pytest.mark.parametrize(
    ("name", "module", "params"),
    [("apf", apf, apf.APFParams()), ("mapf", mapf, mapf.ENVIRONMENT_1)],
    ids=["apf", "mapf"],
)
def test_sarog_differential_drive_goes_round_the_obstacle(name, module, params):
    # The same alignment with paper 3's whole loop (eq. 9, 11, 13, 8 and Table I gains): when
    # the field turns to point backwards, eq. 11 turns the robot while v = k_rho rho > 0
    # keeps it moving, which breaks the symmetry. This holds for APF as much as for MAPF.
    _, min_d, reached = run_diffdrive(module, params, (0.9, 0.0), (1.5, 0.0), steps=1500)
    assert reached is not None, name
    assert min_d > 0.2  # E-puck discs (radius 0.037 m) never touch


def test_gnron_differential_drive_only_mapf_n5_reaches_goal():
    goal, obstacle = (1.5, 0.0), (1.3, 0.0)
    assert run_diffdrive(apf, apf.APFParams(), obstacle, goal, steps=1500)[2] is None
    assert run_diffdrive(mapf, mapf.ENVIRONMENT_1, obstacle, goal, steps=1500)[2] is None  # n = 1 is not enough
    _, min_d, reached = run_diffdrive(mapf, mapf.ENVIRONMENT_2, obstacle, goal, steps=1500)
    assert reached is not None
    assert min_d > 0.1


# ---------------------------------------------------------------- SFM, paper 1 eq. 3-7, 17-20


def test_sfm_goal_force_eq4():
    p = sfm.SFMParams()  # m = 20 kg, tau = 0.1 s, v0 = 2 m/s
    pos, vel, goal = (0.0, 0.0), (0.5, -0.5), (3.0, 4.0)
    e = (0.6, 0.8)
    want = (20.0 * (2.0 * e[0] - 0.5) / 0.1, 20.0 * (2.0 * e[1] + 0.5) / 0.1)  # m (v0 e - v) / tau
    assert sfm.goal_force(pos, vel, goal, p) == pytest.approx(want)  # (140, 420) N
    assert sfm.goal_force(goal, (0.0, 0.0), goal, p) == (0.0, 0.0)


def test_sfm_obstacle_force_eq5_to_7():
    p = sfm.SFMParams(k=100.0, robot_radius=0.5, obstacle_radius=0.0, sigma=0.5)
    # d = 1.0 > r_ij: social force only, k exp((r_ij - d) / sigma) = 100 e^-1 along e_ij (+x here)
    assert sfm.obstacle_force((1.0, 0.0), (0.0, 0.0), 100.0, p) == pytest.approx((100.0 * math.exp(-1.0), 0.0))
    # d = 0.3 < r_ij: social + physical k (r_ij - d) = 100 (e^0.4 + 0.2), along e_ij (-y here)
    fx, fy = sfm.obstacle_force((0.0, 0.0), (0.0, 0.3), 100.0, p)
    assert (fx, fy) == pytest.approx((0.0, -100.0 * (math.exp(0.4) + 0.2)))


def test_sfm_eq3_sums_goal_and_obstacle_forces():
    pos, vel, goal, obstacles = (0.0, 0.0), (0.3, 0.1), (4.0, 1.0), [(1.0, 0.4), (0.5, -0.6)]
    p = sfm.SFMParams(k=300.0)
    gx, gy = sfm.goal_force(pos, vel, goal, p)
    o = [sfm.obstacle_force(pos, ob, 300.0, p) for ob in obstacles]
    want = (gx + o[0][0] + o[1][0], gy + o[0][1] + o[1][1])
    assert sfm.navigation_force(pos, vel, goal, obstacles, p) == pytest.approx(want)


def test_sfm_eq17_to_20_velocity_command():
    # integrate=True: v + F^n tau / m, so in free space the current velocity cancels: v0 e.
    goal = (3.0, 4.0)
    for vel in [(0.0, 0.0), (1.0, -1.0), (0.3, 1.5)]:
        assert sfm.step((0.0, 0.0), vel, goal, []) == pytest.approx((1.2, 1.6))
    # integrate=False is eq. 17 read literally: |F^n| tau / m along F^n, = v0 e - v.
    literal = sfm.SFMParams(integrate=False)
    assert sfm.step((0.0, 0.0), (0.2, 0.1), goal, [], literal) == pytest.approx((1.0, 1.5))
    # eq. 19-20 with the clip to v0
    vx, vy = sfm.command_velocity((0.0, 0.0), (2000.0, 0.0), sfm.SFMParams())
    assert (vx, vy) == pytest.approx((2.0, 0.0))


def test_sfm_pushes_away_from_an_obstacle_left_of_the_path():
    vx, vy = sfm.step((0.0, 0.0), (2.0, 0.0), (5.0, 0.0), [(0.8, 0.2)])
    assert vy < 0.0 < vx
    assert math.hypot(vx, vy) < 2.0


# ---------------------------------------------------------------- F-SFM, paper 1 eq. 8-10, Fig. 4


def test_triangular_membership_eq8():
    mf = fsfm.TriangularMF(0.0, 0.9, 1.5)
    assert mf.degree(0.3) == pytest.approx(0.3 / 0.9)  # (x - u) / (v - u)
    assert mf.degree(0.9) == 1.0
    assert mf.degree(1.2) == pytest.approx(0.5)  # (w - x) / (w - v)
    assert mf.degree(0.0) == 0.0 and mf.degree(1.5) == 0.0 and mf.degree(-1.0) == 0.0
    assert fsfm.TriangularMF(0.0, 0.0, 1.0).degree(-5.0) == 1.0  # left shoulder
    assert fsfm.TriangularMF(0.0, 1.0, 1.0).degree(50.0) == 1.0  # right shoulder
    with pytest.raises(ValueError):
        fsfm.TriangularMF(1.0, 0.5, 2.0)


def test_distance_sets_are_a_partition_crossing_at_halls_boundaries():
    for d in np.linspace(0.0, 10.0, 1001):
        mu = fsfm.memberships(float(d), fsfm.DISTANCE_SETS)
        assert sum(mu) == pytest.approx(1.0), d
        assert sum(m > 0 for m in mu) <= 2, d
    for boundary, (a, b) in [(0.45, (0, 1)), (1.2, (1, 2)), (3.6, (2, 3))]:
        mu = fsfm.memberships(boundary, fsfm.DISTANCE_SETS)
        assert (mu[a], mu[b]) == pytest.approx((0.5, 0.5)), boundary
    # the strongest set is Hall's zone
    for d, zone in [(0.2, "intimate"), (0.8, "personal"), (2.0, "social"), (5.0, "public")]:
        mu = fsfm.memberships(d, fsfm.DISTANCE_SETS)
        assert fsfm.DISTANCE_LABELS[int(np.argmax(mu))] == zone


def test_direction_sets_are_a_partition_crossing_at_30_90_150_degrees():
    for phi in np.linspace(0.0, math.pi, 721):
        assert sum(fsfm.memberships(float(phi), fsfm.DIRECTION_SETS)) == pytest.approx(1.0)
    for deg, (a, b) in [(30, (0, 1)), (90, (1, 2)), (150, (2, 3))]:
        mu = fsfm.memberships(math.radians(deg), fsfm.DIRECTION_SETS)
        assert (mu[a], mu[b]) == pytest.approx((0.5, 0.5)), deg


def test_firing_strengths_eq9_are_products():
    b = fsfm.firing_strengths(0.45, math.pi / 6)
    assert b[0][:2] == pytest.approx([0.25, 0.25]) and b[1][:2] == pytest.approx([0.25, 0.25])
    assert sum(map(sum, b)) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("d", "phi", "label"),
    [
        (0.0, 0.0, "VH"),  # intimate, front
        (0.9, math.pi / 3, "H"),  # personal, side-front
        (1.5, math.pi / 3, "M"),  # social, side-front
        (0.9, 2 * math.pi / 3, "M"),  # personal, side-back
        (5.7, 2 * math.pi / 3, "L"),  # public, side-back
        (20.0, math.pi, "VL"),  # public, back
    ],
)
def test_single_rule_of_fig4_fires_at_set_centres(d, phi, label):
    for outputs in (fsfm.SCHEME_5, fsfm.SCHEME_6):
        assert fsfm.gain(d, phi, fsfm.FIS(outputs=outputs)) == getattr(outputs, label)


def test_centre_of_area_eq10_blends_neighbouring_rules():
    # d on the intimate|personal boundary, front: (VH + H) / 2 = 175 for scheme #5
    assert fsfm.gain(0.45, 0.0) == pytest.approx(175.0)
    # also on the front|side-front boundary: (VH + H + H + H) / 4 = 162.5
    assert fsfm.gain(0.45, math.pi / 6) == pytest.approx(162.5)
    assert fsfm.gain(0.45, -math.pi / 6) == pytest.approx(162.5)  # left and right are symmetric


def test_scheme_6_is_three_times_scheme_5():
    s5 = fsfm.FIS(outputs=fsfm.SCHEME_5)
    s6 = fsfm.FIS(outputs=fsfm.SCHEME_6)
    for d, phi in [(0.3, 0.2), (1.0, 1.0), (2.5, 2.5), (4.0, 0.7)]:
        assert fsfm.gain(d, phi, s6) == pytest.approx(3.0 * fsfm.gain(d, phi, s5))


def test_fsfm_is_sfm_with_the_fis_gain():
    pos, vel, goal, obstacle = (0.0, 0.0), (1.0, 0.0), (4.0, 0.0), (1.0, 0.5)
    p = fsfm.FSFMParams()
    (k,) = fsfm.obstacle_gains(pos, vel, goal, [obstacle], p)
    # obstacle at d = 1.118 m (personal|social), 26.6 degrees off the goal direction (front|side-front)
    assert fsfm.gain(math.hypot(1.0, 0.5), math.atan2(0.5, 1.0), p.fis) == k
    want = sfm.navigation_force(pos, vel, goal, [obstacle], sfm.SFMParams(k=k))
    assert fsfm.navigation_force(pos, vel, goal, [obstacle], p) == pytest.approx(want)


def test_fsfm_obstacle_ahead_weighs_more_than_behind():
    ahead, behind = fsfm.obstacle_gains((0.0, 0.0), (0.0, 0.0), (5.0, 0.0), [(0.8, 0.0), (-0.8, 0.0)])
    assert ahead == pytest.approx(fsfm.gain(0.8, 0.0)) and behind == pytest.approx(fsfm.gain(0.8, math.pi))
    assert ahead > behind


def test_fsfm_front_can_follow_the_velocity():
    goal, obstacle = (5.0, 0.0), (0.0, 0.8)  # 90 degrees off the goal direction, dead ahead of +y motion
    by_goal = fsfm.obstacle_gains((0.0, 0.0), (0.0, 1.0), goal, [obstacle])[0]
    by_vel = fsfm.obstacle_gains((0.0, 0.0), (0.0, 1.0), goal, [obstacle], fsfm.FSFMParams(front="velocity"))[0]
    assert by_vel == pytest.approx(fsfm.gain(0.8, 0.0))
    assert by_goal == pytest.approx(fsfm.gain(0.8, math.pi / 2))
    # too slow to have a direction: falls back to the goal
    slow = fsfm.obstacle_gains((0.0, 0.0), (0.0, 0.01), goal, [obstacle], fsfm.FSFMParams(front="velocity"))[0]
    assert slow == by_goal


# ---------------------------------------------------------------- heading PID, paper 1 eq. 15-16


def test_pid_eq16_worked_steps():
    p = pid.PIDParams(k_p=20.0, k_i=0.05, k_d=50.0)
    out, s = pid.step(pid.PIDState(), beta=0.5, theta=0.0, params=p)
    assert out == pytest.approx(20 * 0.5 + 0.05 * 0.5)  # no derivative on the first step
    out, s = pid.step(s, beta=0.5, theta=0.2, params=p)
    assert out == pytest.approx(20 * 0.3 + 0.05 * 0.8 + 50 * (0.3 - 0.5))
    assert s == pid.PIDState(integral=pytest.approx(0.8), prev_error=pytest.approx(0.3))


def test_pid_error_is_wrapped_the_short_way_eq15():
    assert pid.heading_error(3.0, -3.0) == pytest.approx(6.0 - 2 * math.pi)  # -0.283 rad, not +6
    out, _ = pid.step(pid.PIDState(), 3.0, -3.0, pid.PIDParams(k_i=0.0))
    assert out < 0.0


def test_pid_no_derivative_kick_across_the_seam():
    p = pid.PIDParams(k_p=0.0, k_i=0.0, k_d=1.0)
    s = pid.PIDState(prev_error=math.pi - 0.01)
    out, _ = pid.step(s, beta=-math.pi + 0.01, theta=0.0, params=p)  # err jumps from +pi-0.01 to -pi+0.01
    assert out == pytest.approx(0.02)


def test_pid_output_and_integral_limits():
    p = pid.PIDParams(max_output=3.0, max_integral=1.0)
    out, s = pid.step(pid.PIDState(integral=0.9), 2.0, 0.0, p)
    assert out == 3.0 and s.integral == 1.0


def test_pid_closed_loop_turns_to_the_target():
    # Paper gains, heading integrated from V_theta. Per-step gains: this loop is stable for
    # dt < 2 / (k_p + 2 k_d) = 16.7 ms (k_i neglected); 10 ms here.
    dt, theta, state = 0.01, 0.0, pid.PIDState()
    for _ in range(2000):
        w, state = pid.step(state, 1.0, theta)
        theta += w * dt
    assert theta == pytest.approx(1.0, abs=0.01)


# ---------------------------------------------------------------- kinematics


TWISTS = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.7, -1.3, 2.1), (-2.0, 0.5, -0.4)]


def test_omni3_eq2_worked_example():
    p = omni3.Omni3Params(wheel_radius=0.04, wheel_distance=0.135)
    s = math.sqrt(3) / 2
    assert omni3.inverse(1.0, 0.0, 0.0, p) == pytest.approx([0.0, -s / 0.04, s / 0.04])  # (0, -21.65, 21.65) rad/s
    assert omni3.inverse(0.0, 1.0, 0.0, p) == pytest.approx([-25.0, 12.5, 12.5])
    assert omni3.inverse(0.0, 0.0, 1.0, p) == pytest.approx([0.135 / 0.04] * 3)


def test_omni3_forward_is_eq1_with_its_second_row_corrected():
    R, L = 0.04, 0.135
    fwd = omni3.forward_matrix(omni3.Omni3Params(wheel_radius=R, wheel_distance=L))
    assert fwd[0] == pytest.approx([0.0, -R / math.sqrt(3), R / math.sqrt(3)])  # eq. 1 row 1
    assert fwd[2] == pytest.approx([R / (3 * L)] * 3)  # eq. 1 row 3
    assert fwd[1] == pytest.approx([-2 * R / 3, R / 3, R / 3])  # printed: [-R/3, -2R/3, 2R/3]


@pytest.mark.parametrize("twist", TWISTS)
def test_omni3_round_trip(twist):
    assert omni3.forward(omni3.inverse(*twist)) == pytest.approx(twist)
    wheels = np.array(twist) * 10.0  # eq. 2 is square: any wheel speeds come from one twist
    assert omni3.inverse(*omni3.forward(wheels)) == pytest.approx(wheels)


def test_omni4_eq3_eq4_worked_example():
    # Default X layout: wheels at 45, 135, 225, 315 degrees, l = 0.2 m, r = 0.05 m.
    h = math.sqrt(0.5)
    assert omni4.wheel_linear_speeds(1.0, 0.0, 0.0) == pytest.approx([-h, -h, h, h])  # -sin a_i
    assert omni4.wheel_linear_speeds(0.0, 1.0, 0.0) == pytest.approx([h, -h, -h, h])  # cos a_i
    assert omni4.inverse(1.0, 0.0, 0.0) == pytest.approx([-h / 0.05, -h / 0.05, h / 0.05, h / 0.05])  # +-14.14 rad/s
    assert omni4.inverse(0.0, 0.0, 1.0) == pytest.approx([4.0] * 4)  # l / r = 0.2 / 0.05
    # different wheel radii divide per wheel (eq. 3)
    p = omni4.Omni4Params(wheel_radii=(0.05, 0.05, 0.1, 0.1))
    assert omni4.inverse(0.0, 0.0, 1.0, p) == pytest.approx([4.0, 4.0, 2.0, 2.0])


@pytest.mark.parametrize("twist", TWISTS)
def test_omni4_round_trip(twist):
    assert omni4.forward(omni4.inverse(*twist)) == pytest.approx(twist)


def test_omni4_forward_is_least_squares_for_slipping_wheels():
    wheels = omni4.inverse(0.5, 0.2, 0.3) + np.array([0.4, -0.1, 0.0, 0.3])
    want, *_ = np.linalg.lstsq(omni4.inverse_matrix(), wheels, rcond=None)
    assert omni4.forward(wheels) == pytest.approx(want)


def test_omni4_general_form_reproduces_robotino_eq2():
    p = omni4.Omni4Params(
        wheel_angles=tuple(math.radians(a) for a in (180.0, 60.0, -60.0)), wheel_distance=0.135, wheel_radii=(0.04,) * 3
    )
    assert omni4.inverse_matrix(p) == pytest.approx(omni3.inverse_matrix(omni3.Omni3Params(0.04, 0.135)))


@pytest.mark.parametrize(
    ("inverse", "forward"),
    [(omni3.inverse, omni3.forward), (omni4.inverse, omni4.forward)],
)
def test_saturation_keeps_the_direction_of_motion(inverse, forward):
    twist = np.array([3.0, -1.0, 2.0])
    wheels = inverse(*twist)
    limited = saturate(wheels, 10.0)
    assert np.max(np.abs(limited)) == pytest.approx(10.0)
    scale = saturation_scale(wheels, 10.0)
    assert 0.0 < scale < 1.0
    assert forward(limited) == pytest.approx(scale * twist)  # same direction and turn ratio, slower
    assert saturate(wheels, 1e6) == pytest.approx(wheels)  # under the limit: unchanged
    with pytest.raises(ValueError):
        saturate(wheels, 0.0)


def test_diffdrive_eq13_worked_example_and_inverse():
    p = diffdrive.DiffDriveParams(wheel_radius=0.0205, axle_length=0.052)
    wr, wl = diffdrive.wheel_speeds(0.1, 1.0, p)
    assert (wr, wl) == pytest.approx(((0.1 + 0.026) / 0.0205, (0.1 - 0.026) / 0.0205))  # (6.146, 3.610) rad/s
    assert diffdrive.body_velocity(wr, wl, p) == pytest.approx((0.1, 1.0))


def test_diffdrive_saturation_keeps_curvature():
    v, w = 0.3, 4.0
    wr, wl = saturate(diffdrive.wheel_speeds(v, w), EPUCK_MAX_WHEEL)
    v2, w2 = diffdrive.body_velocity(float(wr), float(wl))
    assert max(abs(wr), abs(wl)) == pytest.approx(EPUCK_MAX_WHEEL)
    assert v2 / w2 == pytest.approx(v / w)


def test_unicycle_eq8_step():
    x, y, th = diffdrive.unicycle_step(1.0, 2.0, math.pi / 2, v=0.5, omega=0.2, dt=0.1)
    assert (x, y, th) == pytest.approx((1.0, 2.05, math.pi / 2 + 0.02))


def test_track_direction_eq9_eq11():
    g = diffdrive.PolarGains(k_rho=1.0, k_alpha=5.0, k_beta=-1.0)
    # field straight ahead along +x: alpha = 0, beta = 0 -> no turn, v = k_rho rho
    assert diffdrive.track_direction(0.0, 1.0, 0.0, rho=0.8, gains=g) == pytest.approx((0.8, 0.0))
    # field along +y, heading 0: alpha = pi/2, beta = -pi/2 -> omega = 5 pi/2 + pi/2
    assert diffdrive.track_direction(0.0, 0.0, 2.0, rho=1.0, gains=g) == pytest.approx((1.0, 3 * math.pi))


# ---------------------------------------------------------------- registry and conformance


def test_registry_names():
    assert set(NAVIGATORS) == {"apf", "mapf", "sfm", "f-sfm"} == set(PARAMS)
    assert get("f-sfm") is fsfm.step
    with pytest.raises(ValueError, match="known: apf"):
        get("rrt")
    with pytest.raises(TypeError):
        NAVIGATORS["x"] = apf.step  # type: ignore[index]


NAMES = sorted(NAVIGATORS)
SCENES = [
    ((0.0, 0.0), (0.0, 0.0), (4.0, 0.0), []),
    ((0.0, 0.0), (1.0, 0.5), (4.0, 1.0), [(0.6, 0.1)]),
    ((1.0, -2.0), (-0.5, 0.5), (-3.0, 2.0), [(0.8, -1.8), (0.0, -1.0), (3.0, 3.0), (-2.9, 2.0), (1.1, -2.1)]),
]


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("scene", range(len(SCENES)))
def test_navigator_contract(name, scene):
    step = NAVIGATORS[name]
    params = PARAMS[name]()
    pos, vel, goal, obstacles = SCENES[scene]
    out = step(pos, vel, goal, obstacles, params)
    assert isinstance(out, tuple) and len(out) == 2 and all(type(c) is float for c in out)
    assert all(math.isfinite(c) for c in out)
    assert math.hypot(*out) <= params.max_speed + 1e-12
    # numpy inputs give the same answer and are not modified; same inputs, same output
    arrays = [np.array(pos), np.array(vel), np.array(goal), np.array(obstacles, dtype=float).reshape(-1, 2)]
    copies = [a.copy() for a in arrays]
    assert step(*arrays, params) == pytest.approx(out)
    for a, c in zip(arrays, copies):
        assert np.array_equal(a, c)
    assert step(pos, vel, goal, obstacles, params) == out
    assert step(pos, vel, goal, obstacles) == out  # the default params are the registered ones


@pytest.mark.parametrize("name", NAMES)
def test_navigator_heads_for_the_goal_in_free_space(name):
    vx, vy = NAVIGATORS[name]((0.0, 0.0), (0.0, 0.0), (3.0, 4.0), [])
    assert vx > 0 and vy > 0 and vx * 4.0 == pytest.approx(vy * 3.0)


@pytest.mark.parametrize("name", NAMES)
def test_navigator_reaches_goal_past_an_offset_obstacle(name):
    obstacles = [(2.0, 0.15)]
    q, min_d, reached = run_point_mass(
        NAVIGATORS[name], PARAMS[name](), (0.0, 0.0), (4.0, 0.0), obstacles, 1000, tol=0.05
    )
    assert reached is not None, f"{name} ended at {q}"
    assert min_d > 0.25, name
