"""The physics package's constants, collision categories and per-robot record.

Collision categories and types: the ball collides with fence, goals and
robots according to its height (ball.py's shape filter); robot i has
collision type `_ROBOT_TYPE0 + i`, so that a contact names its robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pymunk
from pymunk import batch as pmbatch
from pymunk._chipmunk_cffi import ffi, lib  # pymunk 7's own binding of Chipmunk (pyproject: pymunk <8)

from arena.schemas.messages import Cmd

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
_POSITION = pmbatch.BodyFields.POSITION  # a positions-only read: x, y per body, in the snapshot's body order
_CONTROL = pmbatch.BodyFields.VELOCITY | pmbatch.BodyFields.ANGULAR_VELOCITY  # vx, vy, omega per control body

# The per-substep calls straight into Chipmunk, without pymunk's Python wrappers
# around them (its `__setattr__` hook, the batch set-up, `Space.step`'s queues):
# the same C functions with the same arguments, so the same floats, for about a
# third of the Python work of a substep.
# tests/unit/test_physics.py checks them (and `BodyReader`, `ControlWriter`) against pymunk's public API.
step_space = lib.cpSpaceStep  # (space._space, dt): `Space.step` without its add/remove-later queues
unpack = ffi.unpack


def _batched(buf: pmbatch.Buffer, fields: pmbatch.BodyFields) -> Any:
    """pymunk.batch's descriptor of `buf`'s C arrays for `fields`, as its get/set functions build it per call."""
    data = ffi.new("pmBatchedData *")
    data.fields = fields.value
    data.floatArray = buf._float_arr
    data.intArray = buf._int_arr
    return data


class BodyReader:
    """Every body's (x, y, angle, vx, vy, omega), flat, in one C call.

    What `pmbatch.get_space_bodies(space, _ALL_FIELDS, buf)` then
    `memoryview(buf.float_buf()).cast("d").tolist()` gives, with the batch
    descriptor built once instead of on every read. `Space.step` is called
    around it straight through `step_space`, so the space's collision
    callbacks must not add or remove anything (ours only record, and the
    changes they lead to are made after the step). With `fields=_POSITION`,
    every body's (x, y) only.
    """

    __slots__ = ("_space", "_buf", "_data", "_arr", "_each", "_iterate")

    def __init__(self, space: pymunk.Space, fields: pmbatch.BodyFields = _ALL_FIELDS) -> None:
        self._space = space._space
        self._buf = pmbatch.Buffer()  # owns the C arrays the reads fill
        self._data = _batched(self._buf, fields)
        self._arr = self._buf._float_arr
        self._each = lib.cpSpaceEachBody
        self._iterate = ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched")

    def __call__(self) -> list[float]:
        arr = self._arr
        arr.num = 0
        self._each(self._space, self._iterate, self._data)
        return unpack(arr.arr, arr.num)  # type: ignore[no-any-return]


class ControlWriter:
    """Every control body's (vx, vy, omega), set in one C call.

    What `pmbatch.set_space_bodies(space, _CONTROL, buf)` does, with the batch
    descriptor built once: `cpBodySetVelocity` and `cpBodySetAngularVelocity`
    for each body of `space` in turn (in the order they were added), where a
    call of each per robot cost six times as much Python. `space` holds the
    kinematic control bodies alone and is never stepped: the robots' joints
    only read their velocities, as when they were in no space.
    """

    __slots__ = ("_space", "_buf", "_data", "_arr", "_n", "_each", "_iterate")

    def __init__(self, space: pymunk.Space) -> None:
        self._space = space._space
        self._buf = pmbatch.Buffer()
        pmbatch.get_space_bodies(space, _CONTROL, self._buf)  # sizes the C array: three floats a body
        self._data = _batched(self._buf, _CONTROL)
        self._arr = self._buf._float_arr
        self._n = self._arr.num
        self._each = lib.cpSpaceEachBody
        self._iterate = ffi.addressof(lib, "pmSpaceBodySetIteratorFuncBatched")

    def __call__(self, values: list[float]) -> None:
        """Set (vx, vy, omega) of every body, flat, in the order the bodies were added."""
        arr = self._arr
        arr.arr[0 : self._n] = values
        arr.num = 0  # the setter reads from here on
        self._each(self._space, self._iterate, self._data)


@dataclass(eq=False)
class RobotBody:
    """One robot in the physics: its team and number, its Chipmunk body and the kinematic body that drives it."""

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
    carry_from: tuple[float, float] = (0.0, 0.0)  # [m] its centre when its dribbler took the ball
    parked: bool = False  # taken off the field for good (its process died): no commands, no collisions
