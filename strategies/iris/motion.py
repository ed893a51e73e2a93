"""Motion: driving to a target round the robots, and the push guard.

* every motion goes through a navigator of :mod:`arena.navigation` (F-SFM by
  default, paper 1 eq. 3-14) with the robots within `obstacle_range` as
  obstacles, so that robots steer round each other; the heading uses the PID
  of paper 1 eq. 15-16 (:mod:`arena.navigation.pid`), capped below the
  dribbler's 3 rad/s while holding the ball. The closing speed towards an
  opponent, of the robot and of a ball it holds, is capped to what the drive
  can brake to `push_guard` before contact, and to `contact_push` (0) in
  contact (`guard_push`): no pushing fouls, no shoving, no driving the ball
  into an opponent. The guard works on where the robots are now, not where
  the robot saw them `perception_latency` ago (`RobotView.opponents_now` and
  `pose_now`: opponents moved on at their regressed velocities, the robot at
  its odometry velocity).
* static roles (paper 2, "IRIS Role Assignment" and Fig. 5): an outfield
  robot without the ball never drives out of its area, the defender's from
  our goal line to 0.5 m past the centre line, the attacker's from 0.5 m
  behind it to the opponents' goal line; with the ball, attack.py keeps the
  defender in its area (it feeds the attacker or clears at the edge).
"""

from __future__ import annotations

from math import cos, hypot, pi, remainder, sin, sqrt

from arena.navigation.frames import TAU
from arena.schemas.messages import Cmd, Order
from arena.strategies import skills as S
from arena.strategies.iris.params import Vec

_NEG_PI = -pi  # `_heading_pid`: a wrapped angle of -pi is taken as pi


class MotionMixin:
    """Mixin of `IrisRobot`: going somewhere."""

    __slots__ = ()  # the robot's attributes are `IrisRobot`'s slots

    def u(self, order: Order, x: float) -> float:
        return order.attack_dir * x

    def inside(self, pt: Vec, margin: float = 0.3) -> Vec:
        """pt clamped to the field plus `margin` [m] of run-off."""
        hx, hy = self.half_length + margin, self.half_width + margin
        return S.clamp(pt[0], -hx, hx), S.clamp(pt[1], -hy, hy)

    def my_area(self, order: Order) -> tuple[float, float]:
        return self.plan.area  # type: ignore[union-attr]

    def in_area(self, order: Order, pt: Vec, n: int | None = None) -> bool:
        """Static roles: `pt` lies in the Fig. 5 area of robot `n` (default: this robot); dynamic roles,
        the goalkeeper, or a robot with no area in the plan: always."""
        if self.p.dynamic:
            return True
        area = self.plan.area if n is None else self.plan.areas.get(n)  # type: ignore[union-attr]
        if area is None or (n is None and self.role == "goalkeeper"):
            return True
        u = order.attack_dir * pt[0]
        return area[0] <= u <= area[1]

    def drive(
        self,
        tick: int,
        target: Vec,
        heading: float,
        vmax: float,
        *,
        dribbler: bool = False,
        kick: float = 0.0,
        avoid: bool = True,
        extra_obstacles: tuple[Vec, ...] = (),
        gain: float = 0.0,
    ) -> Cmd:
        """Go to `target` [m] facing `heading` [rad] at most at vmax [m/s], steering round robots;
        `gain` [1/s]: drive straight at speed min(vmax, gain * distance) (without it the straight
        speed is the distance per second, capped by `k_pos`)."""
        view, p = self.view, self.p
        x, y, th = view.pose  # type: ignore[misc]
        # target = self.inside(target), inlined
        gx, gy = target
        hx, hy = self._drive_hx, self._drive_hy
        gx = -hx if gx < -hx else hx if gx > hx else gx
        gy = -hy if gy < -hy else hy if gy > hy else gy
        if self._static_area and not view.has_ball:  # paper 2, Fig. 5: a static robot stays in its area
            (lo, hi), d = self.plan.area, self.order.attack_dir  # type: ignore[union-attr]
            u = d * gx
            gx = d * lo if u < lo else d * hi if u > hi else gx
        tx, ty = gx - x, gy - y
        d = hypot(tx, ty)
        vx, vy = tx, ty  # straight at it, at 1 m/s per metre to go (capped below)
        if gain and d > 1e-9:  # straight at it at gain * distance (a tracking robot: blocker, marker)
            k = gain * d
            k = (k if k < vmax else vmax) / d  # min(vmax, gain * d) / d
            vx, vy = tx * k, ty * k
        if avoid and d > p.direct_range:  # round the robots (a call of its own: most drives go straight)
            vx, vy = self._steer(x, y, gx, gy, vx, vy, extra_obstacles)
        speed, cap = hypot(vx, vy), (gain or p.k_pos) * d
        cap = cap if cap < vmax else vmax  # min(vmax, (gain or k_pos) * d)
        if speed > cap and speed > 0.0:
            vx, vy = vx * cap / speed, vy * cap / speed
        c, s, guard = cos(th), sin(th), self._guard
        has_ball = view.has_ball
        if vx != 0.0 or vy != 0.0 or guard[3] < 0.0:  # `guard_push` does nothing for a robot not moving
            nx, ny = view.pose_now  # the guard works on the present: the view is `perception_latency` late
            rng = past = guard[0]  # [m] the guard's box; `past`: how far beyond contact it may cap
            if self._guard_shrinks:
                # The guard's cap at distance d, sqrt(push_guard^2 + 2 brake (d - contact)), exceeds the robot's
                # speed v beyond d = contact + (v^2 - push_guard^2) / (2 brake): farther opponents, which it
                # would leave be (its caps only ever slow the robot), are not asked for (v + 1 ppm and 1 mm
                # more for rounding); a slow robot (arriving, standing at a set piece) asks for few or none.
                v = (speed if speed < cap else cap) * 1.000001  # [m/s] the speed after the cap above
                past = (v * v - guard[2]) / guard[1]
                past = (past if past > 0.0 else 0.0) + 0.001
                rng = p.contact_range + past
                rng = rng if rng < guard[0] else guard[0]
            if has_ball:  # the held ball's box (below) lies within this one grown by its reach: one ask for both
                ball_rng = p.ball_contact_range + past
                ball_rng = (ball_rng if ball_rng < guard[0] else guard[0]) + self.ball_reach
                rng = ball_rng if ball_rng > rng else rng
            near = view.opponents_near(nx, ny, rng)  # those surely outside the box left out
            if near:  # with none near, `_guard_push` leaves the velocity as it is; the opponents farther
                # than the guard asks for are no change to it (above).
                # `_guard_push(near, guard, nx, ny, vx, vy, p.contact_range)` inlined, the same operations (one
                # call less nearly every tick; its test of a robot not moving holds here: see above)
                nrng, rng, brake2, guard2, contact_push, contact = self._guard_body
                for ox, oy in near:
                    dx, dy = ox - nx, oy - ny
                    if not (nrng <= dx <= rng and nrng <= dy <= rng):
                        continue
                    dd = hypot(dx, dy)
                    if 1e-6 < dd < rng:
                        ex, ey = dx / dd, dy / dd
                        closing = vx * ex + vy * ey
                        if closing > contact_push:
                            most = contact_push if dd < contact else sqrt(guard2 + brake2 * (dd - contact))
                            if closing > most:
                                vx -= (closing - most) * ex
                                vy -= (closing - most) * ey
                if has_ball and (vx != 0.0 or vy != 0.0 or guard[3] < 0.0):
                    # the held ball is part of the body (its centre ball_reach ahead): do not push it into an
                    # opponent either
                    bx, by = nx + self.ball_reach * c, ny + self.ball_reach * s
                    vx, vy = _guard_push(near, guard, bx, by, vx, vy, p.ball_contact_range)
        omega = self._heading_pid(heading, th)
        limit = p.dribble_omega if has_ball or dribbler and d < 0.6 else p.max_omega
        omega = -limit if omega < -limit else limit if omega > limit else omega
        # positional, in the fields' order (msgspec looks each keyword's name up): mode "body", no wheel speeds
        return Cmd(tick, "body", c * vx + s * vy, -s * vx + c * vy, omega, [], dribbler, kick)

    def _steer(
        self, x: float, y: float, gx: float, gy: float, vx: float, vy: float, extra_obstacles: tuple[Vec, ...]
    ) -> Vec:
        """`drive` round the robots: the navigator's velocity from (x, y) to (gx, gy) among every other robot
        (`view.others()`: opponents, then teammates) and the extras within `obstacle_range`; with none,
        (vx, vy) as it is (F-SFM's answer would be the straight line at cruise speed)."""
        view = self.view
        near = self.p.obstacle_range
        nnear = -near
        obstacles = []
        for group in (view.opponents, view.mate_obstacles, extra_obstacles):
            for o in group:
                dx = o[0] - x
                if nnear < dx < near:
                    dy = o[1] - y
                    if nnear < dy < near and hypot(dx, dy) < near:
                        obstacles.append(o)
        if obstacles:
            return self.nav((x, y), view.vel, (gx, gy), obstacles, self.nav_params)
        return vx, vy

    def _heading_pid(self, beta: float, theta: float) -> float:
        """The heading PID (paper 1 eq. 15-16) on the robot's memory: `arena.navigation.pid.update` inlined,
        the same float operations in the same order, with its gains and bounds read once (`_pid`); this runs
        every tick."""
        mem = self.mem
        k_p, k_i, k_d, lo_integral, max_integral, lo_output, max_output = self._pid
        err = remainder(beta - theta, TAU)  # eq. 15
        if err == _NEG_PI:
            err = pi
        integral = mem.pid_integral + err
        if not lo_integral < integral < max_integral:
            integral = max(lo_integral, min(max_integral, integral))
        prev = mem.pid_error
        if prev is None:
            derivative = 0.0
        else:
            derivative = remainder(err - prev, TAU)
            if derivative == _NEG_PI:
                derivative = pi
        mem.pid_integral, mem.pid_error = integral, err
        out = k_p * err + k_i * integral + k_d * derivative  # eq. 16
        if not lo_output < out < max_output:
            out = max(lo_output, min(max_output, out))
        return out

    def guard_push(self, x: float, y: float, vx: float, vy: float, contact: float) -> Vec:
        """Cap the closing speed towards every nearby opponent, so that contact is never a pushing foul.

        (x, y) is the point that must not push: the robot's centre (contact at
        `contact_range`) or the centre of the ball it holds (`ball_contact_range`).
        The cap is what the drive can still brake from before the bodies meet:
        v <= sqrt(push_guard^2 + 2 brake (d - contact)) at distance d [m], so
        that the robot arrives at `push_guard` or slower whatever its
        acceleration limit; in contact (d < contact) it is `contact_push`: a
        robot does not shove an opponent along (MSL: charging), so a carrier
        that shields the ball with its body can turn away, and a holder does
        not drive the ball into an opponent (which would knock it loose).
        """
        return _guard_push(self.view.opponents_near(x, y, self._guard[0]), self._guard, x, y, vx, vy, contact)


def _guard_push(
    opponents: list[Vec],
    guard: tuple[float, float, float, float],
    x: float,
    y: float,
    vx: float,
    vy: float,
    contact: float,
) -> Vec:
    """`MotionMixin.guard_push` on the opponents given, with `guard` = (push_guard_range, 2 brake, push_guard^2,
    contact_push): a plain function, so that `drive` fetches the opponents once for the robot and its ball."""
    rng, brake2, guard2, contact_push = guard
    if vx == 0.0 and vy == 0.0 and contact_push >= 0.0:  # not moving: closing on nobody
        return vx, vy
    nrng = -rng
    for ox, oy in opponents:
        dx, dy = ox - x, oy - y
        if not (nrng <= dx <= rng and nrng <= dy <= rng):  # abs(dx) > rng or abs(dy) > rng, without the calls
            continue
        d = hypot(dx, dy)
        if 1e-6 < d < rng:
            ex, ey = dx / d, dy / d
            closing = vx * ex + vy * ey
            if closing <= contact_push:
                continue
            cap = contact_push if d < contact else sqrt(guard2 + brake2 * (d - contact))
            if closing > cap:
                vx -= (closing - cap) * ex
                vy -= (closing - cap) * ey
    return vx, vy
