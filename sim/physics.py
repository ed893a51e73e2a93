"""The engine's physical world: field, fence, goals, ball and robots in pymunk.

What it models (SI units throughout: m, s, kg, rad):

* **Frame.** The field frame of schemas/messages.py: origin at the centre spot,
  x along the length (goal lines at x = +-length/2), y across, theta from +x
  counter-clockwise. The world is top-down 2D with no gravity; only the ball
  has a height z, integrated here (ballistic, z'' = -9.81 m/s^2) for lobs.
* **Static geometry.** A fence `runoff` metres beyond every line; at both ends
  a goal made of two round posts on the goal line (inner distance
  `goal_width`) and a net (two side segments and a back segment at
  `goal_depth` behind the line), so that a ball that enters stays in.
* **Ball.** A dynamic circle. Rolling friction is a constant deceleration
  `rolling_decel`, realised as a pivot joint to the static body whose force is
  capped at mass * rolling_decel (Coulomb friction: it stops the ball exactly,
  without jitter). Restitution `restitution` against fence, posts, net and
  robots. While z >= robot height the ball flies over robots; while
  z >= goal height it also passes over posts and net (shape filters). A lob
  lands, bounces with the same restitution, and rolls on once the bounce is
  below `BOUNCE_STOP`.
* **Robots.** Dynamic rounded squares driven through a kinematic control body
  per robot (the classic pymunk top-down technique): a PivotJoint with
  max_force = mass * max_accel makes the velocity follow the command with
  linear acceleration at most max_accel (field-frame vector norm), a
  GearJoint with max_force = moment * max_alpha does the same for the turn
  rate. The command (`Cmd`) goes through the robot model's wheels
  (`drive.py`: IRIS omni4, paper 2 eq. 3-4, or Robotino omni3, paper 1
  eq. 1-2): a body twist (mode "body") or wheel speeds (mode "wheels",
  forward kinematics) become a body twist within the wheel-speed saturation,
  max_speed and max_omega, turned into the field frame once per tick with
  the heading at mid-tick. Robots collide with each other, the ball, the
  goals and the fence; a robot pushed by another resists with its own drive
  force.
* **Dribbler.** A robot whose dribbler is on captures the ball when it lies in
  front of its front face (within `DRIBBLE_REACH` of it, centred within
  `DRIBBLE_HALF_WIDTH`, low): the ball is pinned just in front of the face by
  a pivot joint and moves with the robot. The holder loses it when its turn
  rate exceeds dribble_max_omega, when the dribbler is switched off, or to a
  challenge: another robot's body touches the ball, or another robot with its
  own dribbler on comes within `CHALLENGE_DIST` of the ball. A robot that lost
  a challenge cannot recapture for `NO_CATCH_S`, nor challenge the new holder
  (by dribbler or body) for `NO_CHALLENGE_S`, so that two robots at one ball do
  not swap it every tick. One holder at a time.
* **Kicker.** A kick fires once per `set_command` whose kick_speed > 0, as soon
  as the robot holds the ball or has it within reach in front: the ball leaves
  along the robot's heading at min(kick_speed, kick_max_speed). A lob splits
  that speed at `lob_angle` into horizontal and vertical launch speed.
  For `NO_CATCH_S` after its kick the kicker's dribbler cannot recapture the
  ball, so a soft pass with the dribbler still on leaves.
* **Play and stoppages.** The engine switches play off (`stop_play`) when
  the referee stops the game and on again at START (`start_play`). While
  play is off the ball is usually pinned to its restart spot (`pin_ball`:
  the referee puts it back if a robot moves it; nobody can capture or kick
  it), nothing counts as a touch, no event is reported and the no-progress
  clock stands still. A new Physics is in play, unpinned.
* **Events.** `step()` advances one control tick and returns the ball events
  of that tick, stamped with the new tick:
  TOUCH when the last toucher (contact, capture or kick) changes, and for
  the first touch after `start_play` (the set piece is taken);
  GOAL when the ball is wholly past a goal line between the posts and crossed
  the line below the crossbar (team: the side attacking that goal, from
  `attack_dir_a`), after which the ball rests in the net until placed;
  GOAL_LINE and TOUCH_LINE when it is wholly over a goal line (elsewhere, or
  over the crossbar) or a touch line: once per crossing, re-armed when the
  ball's centre is back inside the lines or the ball is placed; GOAL_LINE's
  team is the team defending that goal line, so that the referee can tell a
  goal kick from a corner by the last toucher;
  NO_PROGRESS once the ball, in play, has stayed within
  `RulesParams.progress_radius` of one point for `no_progress_s` (default
  `RulesParams.no_progress_s`): idle, or stuck between robots; re-armed when
  it gets out of that circle (which then moves to it) or is placed. Every event carries the ball position and the
  last toucher. Placing the ball keeps the last toucher.
* **Fouls** (reported as events with the offender's team and robot):
  FOUL_PUSHING when two robots of different teams start touching with a
  closing speed above `RulesParams.push_speed` (the normal component of the
  relative velocity at impact); the offender is the one that drove more
  into the other (the larger velocity component towards it), x/y the
  contact point. FOUL_DRIBBLING once per possession when the holder's centre
  gets farther than `RulesParams.dribble_limit` (MSL 3 m, straight line)
  from where it was when its dribbler took the ball; x/y the ball.

Nothing here is random or reads a clock: equal inputs give equal outputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pymunk
from pymunk import batch as pmbatch

from arena.runtime.config import TEAMS, FieldParams, MatchConfig
from arena.schemas.messages import BallEvent, Cmd, RobotState, World
from arena.sim.drive import Drive

GRAVITY = 9.81  # [m/s^2] for the ball's height
FENCE_RADIUS = 0.05  # [m] half-thickness of the fence segments
POST_RADIUS = 0.05  # [m] goal post radius
NET_RADIUS = 0.02  # [m] half-thickness of the net segments
ROBOT_CORNER = 0.01  # [m] corner rounding of the robot footprint (keeps contacts stable)
ROBOT_FRICTION = 0.5  # [-] robot against robot, goal and fence (product rule)
WALL_FRICTION = 0.5  # [-]
COLLISION_SLOP = 0.002  # [m] overlap pymunk tolerates before pushing shapes apart
SOLVER_ITERATIONS = 10  # [-] pymunk solver iterations per substep

DRIBBLE_REACH = 0.10  # [m] ball surface to front face, still in reach
DRIBBLE_SLACK = 0.02  # [m] tolerated penetration of the ball into the front face
DRIBBLE_HALF_WIDTH = 0.15  # [m] lateral offset of the ball centre still "in front"
CATCH_MAX_Z = 0.11  # [m] a ball higher than this cannot be captured or kicked
HOLD_GAP = 0.005  # [m] held ball's surface to the front face
CHALLENGE_DIST = 0.20  # [m] challenger's footprint edge to the ball's surface
BOUNCE_STOP = 0.5  # [m/s] vertical speed below which a landing ball stops bouncing
NO_CATCH_S = 0.25  # [s] after its own kick or a lost challenge a dribbler cannot capture
NO_CHALLENGE_S = 0.16  # [s] after a lost challenge a robot cannot challenge the new holder (no 1-tick ping-pong)
PIN_TOLERANCE = 1e-3  # [m] a pinned ball moved farther than this is put back

_CAT_FENCE = 0b0001
_CAT_GOAL = 0b0010
_CAT_ROBOT = 0b0100
_CAT_BALL = 0b1000
_BALL_TYPE = 1  # collision type of the ball; robot i has collision type _ROBOT_TYPE0 + i
_ROBOT_TYPE0 = 2

_ALL_FIELDS = (
    pmbatch.BodyFields.POSITION
    | pmbatch.BodyFields.ANGLE
    | pmbatch.BodyFields.VELOCITY
    | pmbatch.BodyFields.ANGULAR_VELOCITY
)
_STRIDE = 6  # floats per body in a batch snapshot: x, y, angle, vx, vy, omega


def wrap_angle(a: float) -> float:
    """Angle wrapped to (-pi, pi] [rad]."""
    a = math.remainder(a, math.tau)
    return math.pi if a <= -math.pi else a


@dataclass(eq=False)
class _Robot:
    team: str
    n: int
    body: pymunk.Body
    ctrl: pymunk.Body  # kinematic: its velocity is the commanded velocity
    hold: pymunk.PivotJoint  # ball to front face, in the space while holding
    off: int = 0  # offset of this body in the batch snapshot
    cmd: Cmd | None = None
    twist: tuple[float, float, float] = (0.0, 0.0, 0.0)  # body frame, what `cmd` gives within the limits
    kick_armed: bool = False
    dribbler: bool = False
    dist: float = 0.0  # [m] travelled
    catch_from: int = 0  # first tick at which the dribbler may capture the ball again
    challenge_from: int = 0  # first tick at which it may challenge a holder again
    ctrl_set: tuple[float, float, float] = (0.0, 0.0, 0.0)  # last control velocity written
    carry_from: tuple[float, float] = (0.0, 0.0)  # [m] its centre when its dribbler took the ball


class Physics:
    """The pymunk world of one match; see the module docstring for the model.

    Attributes set by the engine: `attack_dir_a` (+1: team a attacks the +x
    goal, -1: the -x goal) and `no_progress_s` [s]. `tick` counts completed
    steps; `step()` moves the world from `tick` to `tick + 1`. `in_play` is
    switched by `stop_play` and `start_play`.
    """

    def __init__(self, cfg: MatchConfig, no_progress_s: float | None = None) -> None:
        self.cfg = cfg
        self.attack_dir_a = 1
        self.no_progress_s = cfg.rules.no_progress_s if no_progress_s is None else no_progress_s
        self.in_play = True
        self.tick = 0
        f, rp, bp = cfg.field, cfg.robot, cfg.ball
        self._dt = cfg.timing.dt
        self._substeps = cfg.timing.substeps
        self._h = self._dt / self._substeps  # [s] substep
        self._half_len = f.length / 2
        self._half_wid = f.width / 2
        self._half_goal = f.goal_width / 2
        self._goal_height = f.goal_height
        self._robot_height = rp.height
        self._ball_r = bp.radius
        self._ball_e = bp.restitution
        self._face = rp.size / 2 + bp.radius  # [m] robot centre to a touching ball's centre
        self._hold_dist = self._face + HOLD_GAP
        self._challenge = rp.size / 2 + bp.radius + CHALLENGE_DIST  # [m] centre to centre
        self._no_catch_ticks = math.ceil(NO_CATCH_S / self._dt)
        self._no_challenge_ticks = math.ceil(NO_CHALLENGE_S / self._dt)
        self._drive = Drive(rp)
        self._push_speed = cfg.rules.push_speed  # [m/s]
        self._dribble_limit = cfg.rules.dribble_limit  # [m]
        self._progress_radius = cfg.rules.progress_radius  # [m]

        space = pymunk.Space()
        space.iterations = SOLVER_ITERATIONS
        space.collision_slop = COLLISION_SLOP
        self._space = space
        self._add_fence(f)
        for side in (1, -1):
            self._add_goal(f, side)

        self._ball = pymunk.Body(bp.mass, pymunk.moment_for_circle(bp.mass, 0, bp.radius))
        self._ball_shape = pymunk.Circle(self._ball, bp.radius)
        self._ball_shape.elasticity = bp.restitution
        self._ball_shape.friction = 0.0
        self._ball_shape.collision_type = _BALL_TYPE
        self._ball_mask = _CAT_FENCE | _CAT_GOAL | _CAT_ROBOT
        self._ball_shape.filter = pymunk.ShapeFilter(categories=_CAT_BALL, mask=self._ball_mask)
        space.add(self._ball, self._ball_shape)
        self._roll = pymunk.PivotJoint(space.static_body, self._ball, (0, 0), (0, 0))
        self._roll.max_bias = 0.0
        self._roll_force = bp.mass * bp.rolling_decel  # [N]
        self._roll.max_force = self._roll_force
        space.add(self._roll)

        self._robots: list[_Robot] = []
        moment = pymunk.moment_for_box(rp.mass, (rp.size, rp.size))
        side = rp.size - 2 * ROBOT_CORNER
        for team in TEAMS:
            for n in range(cfg.robots):
                body = pymunk.Body(rp.mass, moment)
                shape = pymunk.Poly.create_box(body, (side, side), radius=ROBOT_CORNER)
                shape.elasticity = 0.0  # ball contacts get the ball's restitution in _on_contact
                shape.friction = ROBOT_FRICTION
                shape.collision_type = _ROBOT_TYPE0 + len(self._robots)
                shape.filter = pymunk.ShapeFilter(categories=_CAT_ROBOT)
                space.add(body, shape)
                # The control body stays out of the space: only its velocity matters to
                # the joints, and the batch snapshot then holds just the ball and the robots.
                ctrl = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
                hold = pymunk.PivotJoint(body, self._ball, (self._hold_dist, 0.0), (0.0, 0.0))
                self._robots.append(_Robot(team, n, body, ctrl, hold))
        for i, r in enumerate(self._robots):
            drive = pymunk.PivotJoint(r.ctrl, r.body, (0, 0), (0, 0))
            drive.max_bias = 0.0
            drive.max_force = rp.mass * rp.max_accel
            turn = pymunk.GearJoint(r.ctrl, r.body, 0.0, 1.0)
            turn.max_bias = 0.0
            turn.max_force = moment * rp.max_alpha
            space.add(drive, turn)
            space.on_collision(_BALL_TYPE, _ROBOT_TYPE0 + i, begin=self._on_contact, data=i)
            for j in range(i + 1, len(self._robots)):
                if self._robots[j].team != r.team:
                    space.on_collision(_ROBOT_TYPE0 + i, _ROBOT_TYPE0 + j, begin=self._on_impact, data=(i, j))
        self._by_id = {(r.team, r.n): r for r in self._robots}

        self._buf = pmbatch.Buffer()
        pmbatch.get_space_bodies(space, pmbatch.BodyFields.BODY_ID, self._buf)
        ids = list(memoryview(self._buf.int_buf()).cast("P"))
        self._ball_off = ids.index(self._ball.id) * _STRIDE
        for r in self._robots:
            r.off = ids.index(r.body.id) * _STRIDE
        self._snap: list[float] = []
        self._dirty = True

        # ball state beyond pymunk
        self._z = 0.0  # [m]
        self._vz = 0.0  # [m/s]
        self._airborne = False
        self._holder: _Robot | None = None
        self._dead = False  # after a goal, until placed
        self._out = False  # wholly over a line, until back inside the lines
        self._cross_high = False  # centre crossed the goal line at z >= goal height
        self._prev_ax = 0.0  # [m] |x| of the ball at the previous airborne substep
        self._idle_ticks = 0
        self._idle_fired = False
        self._anchor: tuple[float, float] | None = None  # [m] centre of the no-progress circle
        self._last: _Robot | None = None
        self._touch_armed = False  # the next touch is reported even by the last toucher
        self._carry_fouled = False  # FOUL_DRIBBLING reported for the current possession
        self._pin: tuple[float, float] | None = None
        self._contacts: list[int] = []
        self._impacts: list[tuple[int, float, float]] = []  # offender, contact x, y [m]
        self._events: list[BallEvent] = []
        self._refresh()

    # ------------------------------------------------------------ geometry
    def _add_fence(self, f: FieldParams) -> None:
        x = f.length / 2 + f.runoff + FENCE_RADIUS
        y = f.width / 2 + f.runoff + FENCE_RADIUS
        corners = [(-x, -y), (x, -y), (x, y), (-x, y)]
        for a, b in zip(corners, corners[1:] + corners[:1]):
            self._add_static(pymunk.Segment(self._space.static_body, a, b, FENCE_RADIUS), _CAT_FENCE)

    def _add_goal(self, f: FieldParams, side: int) -> None:
        body = self._space.static_body
        line = side * f.length / 2
        back = side * (f.length / 2 + f.goal_depth + NET_RADIUS)
        post_y = f.goal_width / 2 + POST_RADIUS
        net_y = f.goal_width / 2 + NET_RADIUS
        for s in (1, -1):
            self._add_static(pymunk.Circle(body, POST_RADIUS, (line, s * post_y)), _CAT_GOAL)
            self._add_static(pymunk.Segment(body, (line, s * net_y), (back, s * net_y), NET_RADIUS), _CAT_GOAL)
        self._add_static(pymunk.Segment(body, (back, -net_y), (back, net_y), NET_RADIUS), _CAT_GOAL)

    def _add_static(self, shape: pymunk.Shape, category: int) -> None:
        shape.elasticity = 1.0  # the ball's restitution alone decides its bounce
        shape.friction = WALL_FRICTION
        shape.filter = pymunk.ShapeFilter(categories=category)
        self._space.add(shape)

    # ------------------------------------------------------------- commands
    def set_command(self, team: str, n: int, cmd: Cmd) -> None:
        """Store robot n's latest command; it is applied from the next step on.

        A kick fires at most once per call (when the ball is, or becomes, in reach).
        """
        r = self._by_id[(team, n)]
        r.cmd = cmd
        r.twist = self._drive.twist(cmd)
        r.kick_armed = cmd.kick_speed > 0.0
        r.dribbler = cmd.dribbler

    # ----------------------------------------------------------------- step
    def step(self) -> list[BallEvent]:
        """Advance one control tick (`substeps` pymunk steps); return this tick's events."""
        if self._dirty:
            self._refresh()
        self.tick += 1
        self._events = events = []
        s = self._snap
        self._apply_commands(s)
        space, buf, h = self._space, self._buf, self._h
        robots = self._robots
        for _ in range(self._substeps):
            space.step(h)
            buf.clear()
            pmbatch.get_space_bodies(space, _ALL_FIELDS, buf)
            new = memoryview(buf.float_buf()).cast("d").tolist()
            for r in robots:
                o = r.off
                r.dist += math.hypot(new[o] - s[o], new[o + 1] - s[o + 1])
            s = new
            if self._airborne:
                self._fly(s)
            if self._contacts:
                self._handle_contacts(s)
            if self._impacts:
                self._handle_impacts()
        self._snap = s
        if self._dirty:
            self._refresh()
        self._after_tick()
        return events

    def _apply_commands(self, s: list[float]) -> None:
        half_dt = self._dt / 2
        for r in self._robots:
            o = r.off
            if r.cmd is not None:
                vx, vy, w = r.twist
                theta = s[o + 2] + half_dt * s[o + 5]
                c, sn = math.cos(theta), math.sin(theta)
                target = (c * vx - sn * vy, sn * vx + c * vy, w)
            else:
                target = (0.0, 0.0, 0.0)
            if target != r.ctrl_set:
                r.ctrl.velocity = target[0], target[1]
                r.ctrl.angular_velocity = target[2]
                r.ctrl_set = target
            if self._holder is r and not r.dribbler:
                self._release()
            holder = self._holder
            free = not self._dead and self._pin is None
            if r.kick_armed and free and (holder is r or (holder is None and self._in_reach(r, s))):
                self._kick(r, s)
            elif self._can_capture(r) and self._in_reach(r, s):
                self._capture(r, s)

    def _fly(self, s: list[float]) -> None:
        """One substep of the ball's height; shape filter by height; goal-line crossing height."""
        h = self._h
        self._vz -= GRAVITY * h
        self._z += self._vz * h
        if self._z <= 0.0 and self._vz < 0.0:
            self._z = 0.0
            self._vz = -self._ball_e * self._vz
            if self._vz < BOUNCE_STOP:
                self._vz = 0.0
                self._airborne = False
                if self._holder is None:
                    self._roll.max_force = self._roll_force
        self._set_ball_mask()
        ax = abs(s[self._ball_off])
        if ax < self._half_len:
            self._cross_high = False
        elif self._prev_ax < self._half_len:
            self._cross_high = self._z >= self._goal_height
        self._prev_ax = ax

    def _set_ball_mask(self) -> None:
        if self._dead:
            mask = 0
        else:
            mask = _CAT_FENCE
            if self._z < self._goal_height:
                mask |= _CAT_GOAL
            if self._z < self._robot_height:
                mask |= _CAT_ROBOT
        if mask != self._ball_mask:
            self._ball_mask = mask
            self._ball_shape.filter = pymunk.ShapeFilter(categories=_CAT_BALL, mask=mask)

    def _on_contact(self, arbiter: pymunk.Arbiter, space: pymunk.Space, i: int) -> None:
        arbiter.restitution = self._ball_e
        self._contacts.append(i)

    def _on_impact(self, arbiter: pymunk.Arbiter, space: pymunk.Space, pair: tuple[int, int]) -> None:
        """Robots of different teams start touching: pushing if they close fast enough."""
        a, b = arbiter.shapes
        i, j = pair if a.collision_type == _ROBOT_TYPE0 + pair[0] else pair[::-1]
        nx, ny = arbiter.normal  # from shape a to shape b
        va, vb = a.body.velocity, b.body.velocity
        into_b = va.x * nx + va.y * ny  # [m/s] a's speed towards b
        into_a = -(vb.x * nx + vb.y * ny)
        if into_b + into_a > self._push_speed:
            points = arbiter.contact_point_set.points
            px, py = points[0].point_a if points else a.body.position
            self._impacts.append((i if into_b >= into_a else j, px, py))

    def _handle_impacts(self) -> None:
        for offender, x, y in self._impacts:
            r = self._robots[offender]
            self._event("FOUL_PUSHING", r.team, x, y, robot=r.n)
        self._impacts.clear()

    def _handle_contacts(self, s: list[float]) -> None:
        for i in self._contacts:
            r = self._robots[i]
            holder = self._holder
            if holder is not None and holder is not r:
                if self.tick >= r.challenge_from:
                    self._lose(holder)
            elif self._can_capture(r) and self._in_reach(r, s):
                self._capture(r, s)
            self._touch(r, s)
        self._contacts.clear()

    def _after_tick(self) -> None:
        s = self._snap
        pin = self._pin
        if pin is not None:
            b = self._ball_off
            if self._holder is not None or math.hypot(s[b] - pin[0], s[b + 1] - pin[1]) > PIN_TOLERANCE:
                self.place_ball(*pin)
                s = self._fresh()
        holder = self._holder
        if holder is not None:
            if abs(s[holder.off + 5]) > self.cfg.robot.dribble_max_omega:
                self._release()
            elif self._challenged(holder, s):
                self._lose(holder)
            elif not self._carry_fouled and self._carried_too_far(holder, s):
                self._carry_fouled = True
                b = self._ball_off
                self._event("FOUL_DRIBBLING", holder.team, s[b], s[b + 1], robot=holder.n)
        self._line_events(s)

    def _carried_too_far(self, holder: _Robot, s: list[float]) -> bool:
        x0, y0 = holder.carry_from
        return math.hypot(s[holder.off] - x0, s[holder.off + 1] - y0) > self._dribble_limit

    def _challenged(self, holder: _Robot, s: list[float]) -> bool:
        """Another robot touches the held ball, or wants it (dribbler on) and is close."""
        bx, by, tick = s[self._ball_off], s[self._ball_off + 1], self.tick
        for r in self._robots:
            if (
                r is not holder
                and r.dribbler
                and tick >= r.challenge_from
                and math.hypot(s[r.off] - bx, s[r.off + 1] - by) < self._challenge
            ):
                return True
        for hit in self._space.shape_query(self._ball_shape):
            t = hit.shape.collision_type - _ROBOT_TYPE0
            if t >= 0 and hit.shape.body is not holder.body and tick >= self._robots[t].challenge_from:
                return True
        return False

    def _lose(self, holder: _Robot) -> None:
        holder.catch_from = self.tick + self._no_catch_ticks
        holder.challenge_from = self.tick + self._no_challenge_ticks
        self._release()

    # -------------------------------------------------------- ball handling
    def _can_capture(self, r: _Robot) -> bool:
        return (
            r.dribbler and self._holder is None and not self._dead and self._pin is None and self.tick >= r.catch_from
        )

    def _in_reach(self, r: _Robot, s: list[float]) -> bool:
        if self._z > CATCH_MAX_Z:
            return False
        o, b = r.off, self._ball_off
        dx, dy = s[b] - s[o], s[b + 1] - s[o + 1]
        c, sn = math.cos(s[o + 2]), math.sin(s[o + 2])
        fx = c * dx + sn * dy
        fy = c * dy - sn * dx
        return self._face - DRIBBLE_SLACK <= fx <= self._face + DRIBBLE_REACH and abs(fy) <= DRIBBLE_HALF_WIDTH

    def _capture(self, r: _Robot, s: list[float]) -> None:
        o = r.off
        theta, w = s[o + 2], s[o + 5]
        c, sn = math.cos(theta), math.sin(theta)
        d = self._hold_dist
        self._ball.position = s[o] + d * c, s[o + 1] + d * sn
        self._ball.velocity = s[o + 3] - w * d * sn, s[o + 4] + w * d * c
        self._z = self._vz = 0.0
        self._airborne = False
        self._set_ball_mask()
        self._roll.max_force = 0.0
        self._space.add(r.hold)
        self._holder = r
        r.carry_from = (s[o], s[o + 1])
        self._carry_fouled = False
        self._dirty = True
        self._touch(r, s)

    def _release(self) -> None:
        holder = self._holder
        if holder is None:
            return
        self._space.remove(holder.hold)
        self._holder = None
        if not self._airborne:
            self._roll.max_force = self._roll_force

    def _kick(self, r: _Robot, s: list[float]) -> None:
        r.kick_armed = False
        r.catch_from = self.tick + self._no_catch_ticks
        self._release()
        cmd = r.cmd
        assert cmd is not None
        speed = min(cmd.kick_speed, self.cfg.robot.kick_max_speed)
        theta = s[r.off + 2]
        if cmd.kick_lob:
            flat = speed * math.cos(self.cfg.robot.lob_angle)
            self._vz = speed * math.sin(self.cfg.robot.lob_angle)
            self._z = 0.0
            self._airborne = True
            self._prev_ax = abs(s[self._ball_off])
            self._roll.max_force = 0.0
        else:
            flat = speed
        self._ball.velocity = flat * math.cos(theta), flat * math.sin(theta)
        self._dirty = True
        self._touch(r, s)

    def _touch(self, r: _Robot, s: list[float]) -> None:
        if not self.in_play or (self._last is r and not self._touch_armed):
            return
        self._last = r
        self._touch_armed = False
        b = self._ball_off
        self._events.append(
            BallEvent(
                kind="TOUCH",
                tick=self.tick,
                team=r.team,
                robot=r.n,
                x=s[b],
                y=s[b + 1],
                last_team=r.team,
                last_robot=r.n,
            )
        )

    def _event(self, kind: str, team: str, x: float, y: float, robot: int = -1) -> None:
        if not self.in_play:
            return
        last = self._last
        self._events.append(
            BallEvent(
                kind=kind,
                tick=self.tick,
                team=team,
                robot=robot,
                x=x,
                y=y,
                last_team=last.team if last else "",
                last_robot=last.n if last else -1,
            )
        )

    def _line_events(self, s: list[float]) -> None:
        if self._dead:
            return
        b = self._ball_off
        x, y = s[b], s[b + 1]
        ax, ay = abs(x), abs(y)
        if not self._airborne and ax < self._half_len:
            self._cross_high = False
        if self._out:
            if ax <= self._half_len and ay <= self._half_wid:
                self._out = False
        elif ax > self._half_len + self._ball_r:
            self._out = True
            attacker = "a" if (1 if x > 0 else -1) == self.attack_dir_a else "b"  # of the goal on this side
            if ay < self._half_goal and not self._cross_high:
                self._event("GOAL", attacker, x, y)
                self._stop_in_goal()
                return
            self._event("GOAL_LINE", "b" if attacker == "a" else "a", x, y)  # team: the defender
        elif ay > self._half_wid + self._ball_r:
            self._out = True
            self._event("TOUCH_LINE", "", x, y)
        anchor = self._anchor
        if self._out or self._airborne or not self.in_play:
            self._anchor = None
            self._idle_ticks = 0
            if not self._out:
                self._idle_fired = False
            return
        if anchor is None or math.hypot(x - anchor[0], y - anchor[1]) > self._progress_radius:
            self._anchor = (x, y)
            self._idle_ticks = 0
            self._idle_fired = False
            return
        self._idle_ticks += 1
        if not self._idle_fired and self._idle_ticks * self._dt >= self.no_progress_s - 1e-9:
            self._idle_fired = True
            self._event("NO_PROGRESS", "", x, y)

    def _stop_in_goal(self) -> None:
        self._release()
        self._ball.velocity = 0.0, 0.0
        self._z = self._vz = 0.0
        self._airborne = False
        self._dead = True
        self._set_ball_mask()
        self._dirty = True

    def _refresh(self) -> None:
        """Re-read every body (after placements or mid-tick changes)."""
        self._buf.clear()
        pmbatch.get_space_bodies(self._space, _ALL_FIELDS, self._buf)
        self._snap = memoryview(self._buf.float_buf()).cast("d").tolist()
        self._dirty = False

    # ------------------------------------------------------------ placement
    def place_ball(self, x: float, y: float, vx: float = 0.0, vy: float = 0.0) -> None:
        """Put the ball on the ground at (x, y) [m], rolling at (vx, vy) [m/s] (default: at rest).

        Nobody holds it afterwards, and the line and no-progress events are re-armed.
        """
        self._release()
        self._ball.position = x, y
        self._ball.velocity = vx, vy
        self._ball.angular_velocity = 0.0
        self._z = self._vz = 0.0
        self._airborne = False
        self._dead = False
        self._set_ball_mask()
        self._roll.max_force = self._roll_force
        self._out = abs(x) > self._half_len + self._ball_r or abs(y) > self._half_wid + self._ball_r
        self._cross_high = False
        self._idle_ticks = 0
        self._idle_fired = False
        self._anchor = (x, y)
        self._dirty = True

    def pin_ball(self, x: float, y: float) -> None:
        """Place the ball at rest on (x, y) [m] and keep it there until `start_play`."""
        self.place_ball(x, y)
        self._pin = (x, y)

    def stop_play(self) -> None:
        """The referee stopped the game: no touches, events or no-progress clock until `start_play`."""
        self.in_play = False

    def start_play(self) -> None:
        """START: the ball is free, and the next touch is reported whoever makes it."""
        self.in_play = True
        self._pin = None
        self._touch_armed = True
        self._idle_ticks = 0
        self._idle_fired = False
        self._anchor = None

    def place_robot(self, team: str, n: int, x: float, y: float, theta: float) -> None:
        """Put robot n at rest on (x, y) [m] facing theta [rad]; it drops a held ball."""
        r = self._by_id[(team, n)]
        if self._holder is r:
            self._release()
        r.body.position = x, y
        r.body.angle = theta
        r.body.velocity = 0.0, 0.0
        r.body.angular_velocity = 0.0
        r.ctrl.velocity = 0.0, 0.0
        r.ctrl.angular_velocity = 0.0
        r.ctrl_set = (0.0, 0.0, 0.0)
        self._space.reindex_shapes_for_body(r.body)
        self._dirty = True

    def kickoff_positions(self, kicking_team: str) -> None:
        """Ball on the centre spot; every robot in its own half, facing the opponent goal.

        Goalkeepers stand on their goal line's centre (just inside the field);
        the kicking team's robot 1 stands 0.5 m behind the ball; everybody else
        takes a fixed slot of its own half outside the centre circle.
        """
        f, size = self.cfg.field, self.cfg.robot.size
        half, hw = f.length / 2, f.width / 2
        slots = [  # (depth from the halfway line, y) [m], for robots 1..5
            (f.center_circle_radius + size, 0.0),
            (0.45 * half, 0.5 * hw),
            (0.45 * half, -0.5 * hw),
            (0.7 * half, 0.25 * hw),
            (0.7 * half, -0.25 * hw),
        ]
        self.place_ball(0.0, 0.0)
        for team in TEAMS:
            attack = self.attack_dir_a if team == "a" else -self.attack_dir_a
            theta = 0.0 if attack > 0 else math.pi
            for n in range(self.cfg.robots):
                if n == 0:
                    depth, y = half - size / 2, 0.0
                elif n == 1 and team == kicking_team:
                    depth, y = 0.5, 0.0
                else:
                    depth, y = slots[n - 1]
                self.place_robot(team, n, -attack * depth, y, theta)

    # -------------------------------------------------------------- queries
    def _fresh(self) -> list[float]:
        if self._dirty:
            self._refresh()
        return self._snap

    def robot_states(self) -> list[tuple[str, int, float, float, float, float, float, float]]:
        """Every robot's (team, n, x, y, theta, vx, vy, omega), field frame, in one pass."""
        s = self._fresh()
        return [
            (r.team, r.n, s[r.off], s[r.off + 1], wrap_angle(s[r.off + 2]), s[r.off + 3], s[r.off + 4], s[r.off + 5])
            for r in self._robots
        ]

    def robot_pose(self, team: str, n: int) -> tuple[float, float, float]:
        """(x [m], y [m], theta [rad] in (-pi, pi]) in the field frame."""
        s, o = self._fresh(), self._by_id[(team, n)].off
        return s[o], s[o + 1], wrap_angle(s[o + 2])

    def robot_velocity(self, team: str, n: int) -> tuple[float, float, float]:
        """(vx [m/s], vy [m/s], omega [rad/s]) in the field frame."""
        s, o = self._fresh(), self._by_id[(team, n)].off
        return s[o + 3], s[o + 4], s[o + 5]

    def ball_state(self) -> tuple[float, float, float, float, float, float]:
        """(x, y, z [m], vx, vy, vz [m/s]) in the field frame."""
        s, b = self._fresh(), self._ball_off
        return s[b], s[b + 1], self._z, s[b + 3], s[b + 4], self._vz

    def holder(self) -> tuple[str, int] | None:
        """(team, n) of the robot whose dribbler holds the ball, else None."""
        h = self._holder
        return None if h is None else (h.team, h.n)

    def last_toucher(self) -> tuple[str, int] | None:
        """(team, n) of the last robot that touched, held or kicked the ball, else None."""
        last = self._last
        return None if last is None else (last.team, last.n)

    @property
    def robot_ids(self) -> list[tuple[str, int]]:
        """Every robot as (team, n): team a 0..N-1, then team b."""
        return [(r.team, r.n) for r in self._robots]

    @property
    def distance(self) -> dict[tuple[str, int], float]:
        """{(team, n): metres travelled so far (sum of per-substep displacements)}."""
        return {(r.team, r.n): r.dist for r in self._robots}

    def world(self, tick: int) -> World:
        """Ground truth as the G_V message."""
        s, b, holder, last = self._fresh(), self._ball_off, self._holder, self._last
        robots = [
            RobotState(
                team=r.team,
                robot=r.n,
                x=s[r.off],
                y=s[r.off + 1],
                theta=wrap_angle(s[r.off + 2]),
                vx=s[r.off + 3],
                vy=s[r.off + 4],
                omega=s[r.off + 5],
                has_ball=r is holder,
            )
            for r in self._robots
        ]
        return World(
            tick=tick,
            t=tick * self._dt,
            ball_x=s[b],
            ball_y=s[b + 1],
            ball_z=self._z,
            ball_vx=s[b + 3],
            ball_vy=s[b + 4],
            ball_vz=self._vz,
            robots=robots,
            last_team=last.team if last else "",
            last_robot=last.n if last else -1,
        )
