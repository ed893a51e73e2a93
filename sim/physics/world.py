"""World building: the pymunk space with fence, goals, ball and robots, and the batch snapshot.

* **Static geometry.** A fence `runoff` metres beyond every line; at both ends
  a goal made of two round posts on the goal line (inner distance
  `goal_width`) and a net (two side segments and a back segment at
  `goal_depth` behind the line), so that a ball that enters stays in.
* **Robots.** Dynamic rounded squares driven through a kinematic control body
  per robot (the classic pymunk top-down technique): a PivotJoint with
  max_force = mass * max_accel makes the velocity follow the command with
  linear acceleration at most max_accel (field-frame vector norm), a
  GearJoint with max_force = moment * max_alpha does the same for the turn
  rate. Robots collide with each other, the ball, the goals and the fence; a
  robot pushed by another resists with its own drive force.
* **Snapshot.** A batch read (`BodyReader`) gives every body's
  (x, y, angle, vx, vy, omega) in a flat list; `RobotBody.off` and
  `_ball_off` index it. A tick reads it after its last substep (and after
  any substep with the ball in the air or touched); every substep's positions
  alone, for the distances travelled, go to a second C array.
"""

from __future__ import annotations

import pymunk
from pymunk import batch as pmbatch

from arena.config import TEAMS, BallParams, FieldParams, RobotParams
from arena.sim.physics.bodies import (
    _BALL_TYPE,
    _CAT_BALL,
    _CAT_FENCE,
    _CAT_GOAL,
    _CAT_ROBOT,
    _POSITION,
    _ROBOT_TYPE0,
    _STRIDE,
    COLLISION_SLOP,
    FENCE_RADIUS,
    NET_RADIUS,
    POST_RADIUS,
    ROBOT_CORNER,
    ROBOT_FRICTION,
    SOLVER_ITERATIONS,
    WALL_FRICTION,
    BodyReader,
    ControlWriter,
    RobotBody,
)


class WorldBuilding:
    """Mixin of `Physics`: builds the space once and re-reads the bodies."""

    def _build_world(self, f: FieldParams, rp: RobotParams, bp: BallParams) -> None:
        """The pymunk space: fence, goals, ball with its rolling friction, robots with their drive joints."""
        cfg = self.cfg
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

        self._robots: list[RobotBody] = []
        controls = pymunk.Space()
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
                # It is in a space of its own, never stepped, where one call sets them all.
                ctrl = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
                controls.add(ctrl)
                hold = pymunk.PivotJoint(body, self._ball, (self._hold_dist, 0.0), (0.0, 0.0))
                self._robots.append(RobotBody(team, n, body, ctrl, hold))
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
        self.robot_index = {
            (r.team, r.n): i for i, r in enumerate(self._robots)
        }  # (team, n) -> its place in `robot_ids`
        self._batch_io(space, controls)

    def _batch_io(self, space: pymunk.Space, controls: pymunk.Space) -> None:
        """The batch reads of the bodies (offsets into the snapshot) and the control bodies' writer."""
        ids_buf = pmbatch.Buffer()
        pmbatch.get_space_bodies(space, pmbatch.BodyFields.BODY_ID, ids_buf)
        ids = list(memoryview(ids_buf.int_buf()).cast("P"))
        self._read = BodyReader(space)
        self._controls = controls  # (the writer holds only its C pointer)
        self._set_controls = ControlWriter(controls)  # every robot's commanded (vx, vy, omega), model.py
        self._positions = BodyReader(space, _POSITION)  # each substep's (x, y), for the distances (model.py `step`)
        self._space_c = space._space
        self._ball_off = ids.index(self._ball.id) * _STRIDE
        for r in self._robots:
            r.off = ids.index(r.body.id) * _STRIDE
        self._snap: list[float] = []
        self._dirty = True
        self._states_of: list[float] | None = None  # the snapshot `_states` was built from (state.py `robot_states`)
        self._states: list[tuple[str, int, float, float, float, float, float, float]] = []

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

    def _refresh(self) -> None:
        """Re-read every body (after placements or mid-tick changes)."""
        self._snap = self._read()
        self._dirty = False

    def _fresh(self) -> list[float]:
        if self._dirty:
            self._refresh()
        return self._snap
