"""The per-tick fast paths give bit for bit what the plain formulas give (matches replay identically)."""

from __future__ import annotations

import math
import random
from dataclasses import replace

from arena.config import MatchConfig
from arena.navigation import fsfm, pid
from arena.navigation.frames import wrap_angle
from arena.schemas.messages import BallSeen, Order, Pose, RobotSeen, Sense, TeamPose
from arena.strategies import registry
from arena.strategies.base import RobotContext
from arena.strategies.world import _CONSECUTIVE, FusionParams, RobotView, _regression_velocity, _unrolled_ahead


def _gain_reference(d: float, phi: float, fis: fsfm.FIS) -> float:
    """Eq. 8-10 straight from the TriangularMF sets (the form `fsfm.gain` inlines)."""
    phi = abs(phi)
    mu_d = [(a, m) for a, s in enumerate(fis.distance_sets) if (m := s.degree(d)) > 0.0]
    num = den = 0.0
    for b, s in enumerate(fis.direction_sets):
        mg = s.degree(phi)
        if mg > 0.0:
            for a, md in mu_d:
                w = mg * md
                num += w * fis.table[b][a]
                den += w
    return num / den


def test_fis_gain_is_bit_identical_to_the_membership_functions():
    rng = random.Random(7)
    edges = [0.0, 0.45, 0.9, 1.2, 1.5, 3.6, 5.7, 9.0, math.pi / 3, 2 * math.pi / 3, math.pi, 5e-324]
    for fis in (fsfm.FIS(), fsfm.FIS(outputs=fsfm.SCHEME_6)):
        for _ in range(20000):
            d = rng.choice(edges) if rng.random() < 0.2 else rng.uniform(0.0, 8.0)
            phi = rng.choice(edges) if rng.random() < 0.2 else rng.uniform(-math.pi, math.pi)
            assert fsfm.gain(d, phi, fis) == _gain_reference(d, phi, fis)


def test_partition_gain_is_bit_identical_to_gain():
    """`fsfm.step`'s gain on the paper's Ruspini partitions gives what `gain`, trying every set, gives."""
    rng = random.Random(8)
    edges = [0.0, 0.45, 0.9, 1.2, 1.5, 3.6, 5.7, 9.0, math.pi / 3, 2 * math.pi / 3, math.pi, 5e-324, math.inf]
    for fis in (fsfm.FIS(), fsfm.FIS(outputs=fsfm.SCHEME_6)):
        dist, dirn = fis.partition
        for _ in range(20000):
            d = rng.choice(edges) if rng.random() < 0.2 else rng.uniform(0.0, 8.0)
            phi = rng.choice(edges) if rng.random() < 0.2 else rng.uniform(0.0, math.pi)
            assert fsfm._partition_gain(d, phi, dist, dirn, fis.table) == fsfm.gain(d, phi, fis)


def test_fsfm_step_is_bit_identical_to_command_velocity_of_navigation_force():
    """The flattened `fsfm.step` gives what its parts give (`sfm.command_velocity` of `navigation_force`)."""
    from arena.navigation.sfm import SFMParams, command_velocity

    social = fsfm.TriangularMF(0.9, 1.5, 6.0)  # reaches past the public set's centre
    shifted = fsfm.FIS(distance_sets=(*fsfm.DISTANCE_SETS[:2], social, fsfm.DISTANCE_SETS[3]))
    assert shifted.partition is None  # not a Ruspini partition: `step` takes the plain path
    params = (
        fsfm.FSFMParams(sfm=SFMParams(max_speed=2.5, robot_radius=0.5, sigma=0.3)),  # the IRIS robots'
        fsfm.SCHEME_6_PARAMS,
        fsfm.FSFMParams(sfm=SFMParams(cutoff_distance=2.0, integrate=False), front="velocity"),
        fsfm.FSFMParams(fis=shifted),
    )
    rng = random.Random(9)
    for p in params:
        assert (p.flat is None) == (p.fis is shifted)
        for _ in range(5000):
            pos = (rng.uniform(-6, 6), rng.uniform(-4, 4))
            vel = rng.choice([(0.0, 0.0), (0.01, -0.02), (rng.uniform(-3, 3), rng.uniform(-3, 3))])
            goal = pos if rng.random() < 0.05 else (rng.uniform(-6, 6), rng.uniform(-4, 4))
            obstacles = []
            for _ in range(rng.randrange(0, 6)):  # some at the distance sets' centres, some on the robot
                r, a = rng.choice([0.0, 0.9, 1.5, 5.7, rng.uniform(0.0, 6.0)]), rng.uniform(-math.pi, math.pi)
                obstacles.append((pos[0] + r * math.cos(a), pos[1] + r * math.sin(a)))
            want = command_velocity(vel, fsfm.navigation_force(pos, vel, goal, obstacles, p), p.sfm)
            assert fsfm.step(pos, vel, goal, obstacles, p) == want
            assert fsfm.step(pos, vel, goal, tuple(obstacles), p) == want


def _pid_reference(state: pid.PIDState, beta: float, theta: float, p: pid.PIDParams) -> tuple[float, pid.PIDState]:
    """Eq. 15-16 as written in the module docstring."""
    err = wrap_angle(beta - theta)
    integral = max(-p.max_integral, min(p.max_integral, state.integral + err))
    derivative = 0.0 if state.prev_error is None else wrap_angle(err - state.prev_error)
    out = p.k_p * err + p.k_i * integral + p.k_d * derivative
    return max(-p.max_output, min(p.max_output, out)), pid.PIDState(integral=integral, prev_error=err)


def test_pid_update_is_bit_identical_to_eq_16():
    rng = random.Random(3)
    params = (
        pid.PIDParams(),
        pid.PIDParams(k_p=6.0, k_i=0.0, k_d=2.0),
        pid.PIDParams(max_output=2.0, max_integral=0.5),
    )
    for p in params:
        a = b = pid.PIDState()
        for _ in range(5000):
            beta, theta = rng.uniform(-4.0, 4.0), rng.choice([math.pi, -math.pi, rng.uniform(-4.0, 4.0)])
            out_a, a = pid.step(a, beta, theta, p)
            out_b, b = _pid_reference(b, beta, theta, p)
            assert (out_a, a) == (out_b, b)
            assert math.copysign(1.0, out_a) == math.copysign(1.0, out_b)


def test_the_robots_heading_pid_is_bit_identical_to_pid_update():
    cfg = MatchConfig()
    rng = random.Random(5)
    for p in (pid.PIDParams(), pid.PIDParams(max_output=2.0, max_integral=0.5)):
        robot = registry.get("AD").make_robot(RobotContext(cfg=cfg, team="a", n=1, rng=random.Random(0)))
        robot.p = replace(robot.p, heading_pid=p)
        robot._pid = (p.k_p, p.k_i, p.k_d, -p.max_integral, p.max_integral, -p.max_output, p.max_output)
        integral, prev = 0.0, None
        for _ in range(5000):
            beta, theta = rng.uniform(-4.0, 4.0), rng.choice([math.pi, -math.pi, rng.uniform(-4.0, 4.0)])
            out, integral, prev = pid.update(integral, prev, beta, theta, p)
            assert robot._heading_pid(beta, theta) == out
            assert (robot.mem.pid_integral, robot.mem.pid_error) == (integral, prev)


def test_robot_view_merges_the_order_with_own_detections():
    cfg = MatchConfig()
    view = RobotView("a", 1, cfg.sensor, cfg.timing.dt, FusionParams())
    order = Order(
        tick=10,
        robot=1,
        command="START",
        attack_dir=1,
        own=[TeamPose(robot=0, x=-5.5, y=0.0), TeamPose(robot=1, x=0.0, y=0.0), TeamPose(robot=2, x=2.0, y=1.0)],
        opponents=[
            TeamPose(robot=-1, x=1.0, y=0.0, age=0),
            TeamPose(robot=-1, x=3.0, y=-2.0, age=0),
            TeamPose(robot=-1, x=4.0, y=2.0, age=500),
        ],
    )
    sense = Sense(
        tick=12,
        pose=Pose(x=0.0, y=0.0, theta=0.0),
        ball=BallSeen(visible=False),
        robots=[RobotSeen(team="b", x=1.1, y=0.1), RobotSeen(team="a", x=2.1, y=1.0)],
    )
    view.update(12, sense, order)
    assert view.opponents == [(1.1, 0.1), (3.0, -2.0)]  # (1, 0) is the own detection; (4, 2) is too old
    assert view.mate_obstacles == [(2.1, 1.0), (-5.5, 0.0)]  # (2, 1) is the own detection
    assert view.others() == view.opponents + view.mate_obstacles


def test_an_order_listing_a_robot_twice_gives_its_last_entry_once():
    cfg = MatchConfig()
    view = RobotView("a", 1, cfg.sensor, cfg.timing.dt, FusionParams())
    own = [TeamPose(robot=2, x=2.0, y=1.0, role="attacker"), TeamPose(robot=0, x=-5.5, y=0.0)]
    own.append(TeamPose(robot=2, x=3.0, y=-1.0, role="defender"))
    opponents = [TeamPose(robot=-1, x=1.0, y=0.0, age=-5), TeamPose(robot=-1, x=4.0, y=2.0, age=-1)]
    order = Order(tick=10, robot=1, command="START", own=own, opponents=opponents)
    view.update(12, Sense(tick=12, pose=Pose(x=0.0, y=0.0, theta=0.0)), order)
    assert view.mates == {2: (3.0, -1.0, "defender"), 0: (-5.5, 0.0, "")}
    assert view.mate_obstacles == [(3.0, -1.0), (-5.5, 0.0)]
    assert view.opponents == [(1.0, 0.0), (4.0, 2.0)]  # negative ages (a bad order): none too old


def test_the_unrolled_prediction_is_the_regression_loops_bit_for_bit():
    """`_unrolled_ahead(n, ...)` moves a consecutive track's last detection by `_regression_velocity` bit for bit."""
    rng = random.Random(3)
    for n in range(3, 65):
        _, stt = _CONSECUTIVE[n]
        for dt, latency in ((0.02, 3), (0.01, 1), (0.01, 7)):
            lead = latency * dt
            ahead = _unrolled_ahead(n, stt * dt, lead)
            for _ in range(50):
                t0 = rng.randrange(0, 100000)
                x0, y0, vx, vy = rng.uniform(-6, 6), rng.uniform(-4, 4), rng.uniform(-3, 3), rng.uniform(-3, 3)
                xs = [x0 + vx * dt * i + rng.gauss(0, 0.03) for i in range(n)]
                ys = [y0 + vy * dt * i + rng.gauss(0, 0.03) for i in range(n)]
                rvx, rvy = _regression_velocity(list(range(t0, t0 + n)), xs, ys, dt)
                assert ahead(xs, ys) == (xs[-1] + rvx * lead, ys[-1] + rvy * lead)


def test_segment_room_is_the_least_segment_distance_bit_for_bit():
    """`best_aim`'s `segment_room` gives what `min(segment_distance(...)[0] ...)` gives."""
    from arena.strategies.skills import segment_distance, segment_room

    rng = random.Random(11)
    for _ in range(20000):
        a = (rng.uniform(-6, 6), rng.uniform(-4, 4))
        b = a if rng.random() < 0.05 else (rng.uniform(-6, 6), rng.uniform(-4, 4))  # a point-like segment too
        points = [(rng.uniform(-7, 7), rng.uniform(-5, 5)) for _ in range(rng.randrange(0, 7))]
        expected = min((segment_distance(q, a, b)[0] for q in points), default=math.inf)
        assert segment_room(points, a, b) == expected


def _guard_box(points: list[tuple[float, float]], x: float, y: float, rng: float) -> list[tuple[float, float]]:
    """What the push guard keeps: the points within rng of (x, y) along both axes."""
    return [(ox, oy) for ox, oy in points if not (abs(ox - x) > rng or abs(oy - y) > rng)]


def test_opponents_near_leaves_out_only_opponents_outside_the_box():
    """`opponents_near` skips predicting far tracks; what it keeps, in the box, is `opponents_now` bit for bit."""
    cfg = MatchConfig()
    rng = random.Random(5)
    order = Order(tick=0, robot=1, opponents=[TeamPose(robot=-1, x=-4.0, y=2.0), TeamPose(robot=-1, x=5.0, y=-3.0)])
    for _ in range(200):
        views = [RobotView("a", 1, cfg.sensor, cfg.timing.dt, FusionParams(), latency=3) for _ in range(2)]
        movers = [(rng.uniform(-5, 5), rng.uniform(-3, 3), rng.uniform(-4, 4), rng.uniform(-4, 4)) for _ in range(3)]
        for k in range(rng.randrange(1, 16)):
            noise = 0.05 if rng.random() < 0.5 else 0.0
            robots = [
                RobotSeen(
                    team="b", x=x + vx * 0.02 * k + rng.gauss(0, noise), y=y + vy * 0.02 * k + rng.gauss(0, noise)
                )
                for x, y, vx, vy in movers
                if rng.random() < 0.95  # now and then one is not seen: a gap in its track, or a new track
            ]
            sense = Sense(tick=k, pose=Pose(x=0.0, y=0.0, theta=0.0), robots=robots)
            for view in views:
                view.update(k + 3, sense, order)
        now = views[0].opponents_now
        near = views[1]
        for ox, oy in now:  # boxes whose edge passes within a few cm of a prediction, and farther ones
            for r in (0.4, 2.5):
                sx, sy = rng.choice((-1, 1)) * (r + rng.uniform(-0.03, 0.03)), rng.uniform(-r, r)
                for cx, cy in ((ox + sx, oy + sy), (ox + sy, oy + sx), (ox + 3 * sx, oy)):
                    kept = near.opponents_near(cx, cy, r)
                    assert _guard_box(kept, cx, cy, r) == _guard_box(now, cx, cy, r)
                    assert all(p in now for p in kept)


def test_drive_narrows_the_push_guard_to_the_opponents_it_may_cap():
    """`drive` asks once (for the robot and the ball it holds) and only for the opponents within the distance
    where the guard's cap rises above the robot's speed: the same commands, bit for bit, as the guard over
    every opponent, while fewer opponents are asked for."""
    import msgspec

    cfg = MatchConfig()
    rng = random.Random(12)
    make = registry.get("AD").make_robot
    asked: list[list[int]] = [[], []]  # per ask: how many opponents it got, and how many there are
    for _ in range(500):
        x0, y0 = rng.uniform(-3, 3), rng.uniform(-2, 2)
        # headings and courses along an axis too: an opponent that far along it is at the edge of the box asked for
        th = rng.choice((0.0, math.pi / 2, -math.pi, rng.uniform(-3, 3)))
        has_ball = rng.random() < 0.4
        a = rng.choice((0.0, math.pi / 2, -math.pi, rng.uniform(-3, 3)))
        a = th + rng.choice((0.0, rng.uniform(-0.3, 0.3))) if has_ball else a
        vmax = rng.choice((0.3, 0.6, 1.0, 1.5, 2.0, 2.5))
        past = max(vmax * vmax - 0.25, 0.0) / 2.4  # [m] beyond contact the guard's cap passes vmax
        r, rb = (0.65 + past) * rng.uniform(0.99, 1.01), (0.4 + past) * rng.uniform(0.99, 1.01) + 0.335
        movers = [(x0 + r * math.cos(a), y0 + r * math.sin(a), 0.0, 0.0)]  # ahead, about where the cap passes vmax
        movers += [(x0 + rb * math.cos(th), y0 + rb * math.sin(th), 0.0, 0.0)]  # the same ahead of the ball
        movers += [(x0 + rng.uniform(-3, 3), y0 + rng.uniform(-3, 3), rng.uniform(-2, 2), rng.uniform(-2, 2))]
        order = Order(tick=0, robot=1, command="START", attack_dir=1, own=[TeamPose(robot=1, x=x0, y=y0)])
        robots = [make(RobotContext(cfg=cfg, team="a", n=1, rng=random.Random(0))) for _ in range(2)]
        for k in range(rng.randrange(3, 12)):  # tracks of 3 detections or more: the box applies
            seen = [RobotSeen(team="b", x=x + vx * 0.02 * k, y=y + vy * 0.02 * k) for x, y, vx, vy in movers]
            sense = Sense(tick=k, pose=Pose(x=x0, y=y0, theta=th), robots=seen, has_ball=has_ball)
            for robot in robots:
                robot.view.update(k + 3, sense, order)
                robot.order, robot.plan = order, robot.make_plan(order)
        view, every = robots[0].view, robots[1].view.opponents_now
        near = view.opponents_near
        view.opponents_near = lambda x, y, r, near=near: asked[0].append(len(z := near(x, y, r))) or z
        robots[1].view.opponents_near = lambda x, y, r, every=every: asked[1].append(len(every)) or every
        target = (x0 + 4.0 * math.cos(a), y0 + 4.0 * math.sin(a))
        for gain in (0.0, 3.0):
            cmds = [robot.drive(5, target, a, vmax, avoid=False, gain=gain, dribbler=has_ball) for robot in robots]
            assert msgspec.msgpack.encode(cmds[0]) == msgspec.msgpack.encode(cmds[1])
    assert len(asked[0]) == len(asked[1]) and sum(asked[0]) < 0.9 * sum(asked[1])


def _tracked_reference(old: list, seen: list, tick: int, merge2: float, window: int) -> list:
    """`RobotView._track` as plain formulas: each detection continues the nearest track within merge_radius."""
    old, out = [(list(ts), list(xs), list(ys)) for _, _, ts, xs, ys, _ in old], []
    for x, y in seen:
        best, best_d2 = None, merge2
        for t in old:
            d2 = (t[1][-1] - x) ** 2 + (t[2][-1] - y) ** 2
            if d2 < best_d2:
                best, best_d2 = t, d2
        if best is None:
            out.append((x, y, [tick], [x], [y]))
            continue
        old.remove(best)
        for col, v in zip(best, (tick, x, y)):
            if len(col) >= window:
                del col[0]
            col.append(v)
        out.append((x, y, *best))
    return out


def test_tracking_skips_only_pairs_surely_beyond_the_merge_radius():
    """`_track` leaves out the distance of a pair farther apart along x than merge_radius; it continues the same
    tracks as the plain nearest-within-merge_radius rule, pairs at the radius's edge included."""
    cfg = MatchConfig()
    rng = random.Random(9)
    for radius in (0.5, 0.3, 1e-3):
        view = RobotView("a", 1, cfg.sensor, cfg.timing.dt, FusionParams(merge_radius=radius), latency=3)
        last: list = []  # the detections of the tick before
        for tick in range(1, 400):
            seen = []
            for _ in range(rng.randrange(0, 4)):
                if last and rng.random() < 0.7:  # near a track's last detection, often at the radius along x
                    a, b = rng.choice(last)
                    dx = rng.choice((radius, -radius, math.nextafter(radius, 0), rng.uniform(-radius, radius)))
                    seen.append((a + dx, b + rng.choice((0.0, rng.uniform(-0.01, 0.01)))))
                else:
                    seen.append((rng.uniform(-6, 6), rng.uniform(-4, 4)))
            expected = _tracked_reference(view._tracks, seen, tick, view._merge2, view._window)
            view._track(tick, seen)
            last = seen
            assert [tuple(t[:5]) for t in view._tracks] == expected  # the last field: the prediction, kept


def test_the_base_stations_ball_is_the_first_cluster_of_its_detections_bit_for_bit():
    """`TeamModel.update`'s inlined ball fusion gives `cluster(detections, inf)[0]`, weights as `detection_sigma`'s."""
    from arena.config import SensorParams
    from arena.schemas.messages import Report
    from arena.strategies.world import TeamModel, cluster, detection_sigma

    rng = random.Random(13)
    sensor = SensorParams()
    for _ in range(500):
        m = TeamModel("a", 3, sensor, 0.02)
        reports, balls = {}, []
        for n in range(rng.randrange(1, 4)):
            px, py, bx, by = rng.uniform(-6, 6), rng.uniform(-4, 4), rng.uniform(-6, 6), rng.uniform(-4, 4)
            pose = Pose(x=px, y=py, theta=0.0)
            reports[n] = Report(tick=10, robot=n, pose=pose, ball=BallSeen(visible=True, x=bx, y=by))
            s = detection_sigma(sensor, math.hypot(bx - px, by - py))
            balls.append((bx, by, 1.0 / (s * s)))
        m.update(10, reports)
        assert m.ball_xy(10) == cluster(balls, math.inf)[0][:2]


def test_an_orders_opponents_are_dropped_once_older_than_the_memory_tick_by_tick():
    """`update` keeps the order's opponents while age + (tick - order.tick) <= opponent_memory, each on its own."""
    cfg = MatchConfig()
    p = FusionParams(opponent_memory=10)
    view = RobotView("a", 1, cfg.sensor, cfg.timing.dt, p, latency=3)
    ages = (0, 4, 9, 2)
    order = Order(
        tick=5,
        robot=1,
        own=[TeamPose(robot=1, x=0.0, y=0.0)],
        opponents=[TeamPose(robot=-1, x=float(i), y=1.0, age=a) for i, a in enumerate(ages)],
    )
    kept = []
    for tick in range(5, 20):
        view.update(tick, None, order)
        assert view.opponents == [(float(i), 1.0) for i, a in enumerate(ages) if a + tick - 5 <= 10]
        kept.append(len(view.opponents))
    assert kept[0] == 4 and kept[-1] == 0 and len(set(kept)) == 5  # every age leaves at its own tick
