"""`Physics`: one match's pymunk world, stepped one control tick at a time.

The class is assembled from one mixin per concern (world.py, ball.py,
possession.py, events.py, state.py); this module holds its state, the
commands and the step. A command (`Cmd`) goes through the robot model's
wheels (`sim/drive.py`: IRIS omni4, paper 2 eq. 3-4, or Robotino omni3,
paper 1 eq. 1-2): a body twist (mode "body") or wheel speeds (mode
"wheels", forward kinematics) become a body twist within the wheel-speed
saturation, max_speed and max_omega, turned into the field frame once per
tick with the heading at mid-tick."""

from __future__ import annotations

import math

from arena.config import MatchConfig
from arena.schemas.messages import BallEvent, Cmd
from arena.sim.drive import Drive
from arena.sim.physics.ball import BallFlight
from arena.sim.physics.bodies import (
    CHALLENGE_DIST,
    HOLD_GAP,
    NO_CATCH_S,
    NO_CHALLENGE_S,
    PIN_TOLERANCE,
    RobotBody,
    step_space,
    unpack,
)
from arena.sim.physics.events import Events
from arena.sim.physics.placement import Placement
from arena.sim.physics.possession import Possession
from arena.sim.physics.state import State
from arena.sim.physics.world import WorldBuilding


class Physics(WorldBuilding, BallFlight, Possession, Events, Placement, State):
    """The pymunk world of one match; see the package docstring for the model.

    Attributes set by the engine: `attack_dir_a` (+1: team a attacks the +x
    goal, -1: the -x goal) and `no_progress_s` [s]. `tick` counts completed
    steps; `step()` moves the world from `tick` to `tick + 1`. `in_play` is
    switched by `stop_play` and `start_play`.
    """

    # slots: an instance dict of 30 keys or more loses CPython 3.11's shared keys, and every method call
    # on the instance then costs ~250 instructions more
    __slots__ = (
        "cfg attack_dir_a no_progress_s in_play tick _dt _substeps _h _half_len _half_wid _half_goal _touch_reach "
        "_goal_height _robot_height _ball_r _ball_e _face _hold_dist _challenge _no_catch_ticks "
        "_no_challenge_ticks _drive _push_speed _dribble_limit _progress_radius _space _ball _ball_shape "
        "_ball_mask _roll _roll_force _robots _by_id robot_index _read _controls _set_controls _positions "
        "_space_c _ball_off _snap _dirty _states_of _states _z _vz _airborne _holder _dead _out _cross_high "
        "_prev_ax _idle_ticks _idle_fired _anchor _last _touch_armed _carry_fouled _pin _contacts _impacts "
        "_events"
    ).split()

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
        # [m] centre to centre beyond which a robot's footprint (a square of side size, circumscribed
        # radius size / sqrt(2)) cannot touch the ball; 0.75 and 1 cm keep it well on the safe side
        self._touch_reach = 0.75 * rp.size + bp.radius + 0.01
        self._no_catch_ticks = math.ceil(NO_CATCH_S / self._dt)
        self._no_challenge_ticks = math.ceil(NO_CHALLENGE_S / self._dt)
        self._drive = Drive(rp)
        self._push_speed = cfg.rules.push_speed  # [m/s]
        self._dribble_limit = cfg.rules.dribble_limit  # [m]
        self._progress_radius = cfg.rules.progress_radius  # [m]

        self._build_world(f, rp, bp)

        # ball state beyond pymunk
        self._z = 0.0  # [m]
        self._vz = 0.0  # [m/s]
        self._airborne = False
        self._holder: RobotBody | None = None
        self._dead = False  # after a goal, until placed
        self._out = False  # wholly over a line, until back inside the lines
        self._cross_high = False  # centre crossed the goal line at z >= goal height
        self._prev_ax = 0.0  # [m] |x| of the ball at the previous airborne substep
        self._idle_ticks = 0
        self._idle_fired = False
        self._anchor: tuple[float, float] | None = None  # [m] centre of the no-progress circle
        self._last: RobotBody | None = None
        self._touch_armed = False  # the next touch is reported even by the last toucher
        self._carry_fouled = False  # FOUL_DRIBBLING reported for the current possession
        self._pin: tuple[float, float] | None = None
        self._contacts: list[int] = []
        self._impacts: list[tuple[int, float, float]] = []  # offender, contact x, y [m]
        self._events: list[BallEvent] = []
        self._refresh()

    def set_command(self, team: str, n: int, cmd: Cmd) -> None:
        """Store robot n's latest command; it is applied from the next step on.

        A kick fires at most once per call (when the ball is, or becomes, in reach).
        """
        self.command((team, n), cmd)

    def command(self, robot: tuple[str, int], cmd: Cmd) -> None:
        """`set_command(*robot, cmd)`, for a caller that holds the (team, n) pair (the engine, six times a tick)."""
        r = self._by_id[robot]
        if r.parked:
            return
        r.cmd = cmd
        r.twist = self._drive.twist(cmd)
        r.kick_armed = cmd.kick_speed > 0.0
        r.dribbler = cmd.dribbler

    def step(self) -> list[BallEvent]:
        """Advance one control tick (`substeps` pymunk steps); return this tick's events."""
        if self._dirty:
            self._refresh()
        self.tick += 1
        self._events = events = []
        s0 = s = self._snap
        self._apply_commands(s)
        space, h, last = self._space_c, self._h, self._substeps - 1
        # `self._read()` (bodies.py BodyReader), inlined. A substep reads every body only when
        # something needs it (the last, the ball in the air, a contact); the robots' distances
        # need only positions: every substep's are appended to one C array, unpacked once a tick.
        rd, pos = self._read, self._positions
        arr, each, bodies, iterate, data = rd._arr, rd._each, rd._space, rd._iterate, rd._data
        parr, pdata, peach = pos._arr, pos._data, pos._each
        parr.num = 0
        for i in range(self._substeps):
            step_space(space, h)
            peach(bodies, iterate, pdata)
            if i == last or self._airborne or self._contacts:
                arr.num = 0
                each(bodies, iterate, data)
                s = unpack(arr.arr, arr.num)
                if self._airborne:
                    self._fly(s)
                if self._contacts:
                    self._handle_contacts(s)
            if self._impacts:
                self._handle_impacts()
        self._add_distances(s0, unpack(parr.arr, parr.num))
        self._snap = s
        if self._dirty:
            self._refresh()
        self._after_tick()
        return events

    def _add_distances(self, s: list[float], p: list[float]) -> None:
        """Each robot's distance, from `s` (the tick's start) through each substep's positions `p`.

        The same additions as one per robot per substep, robot by robot: a robot's sum sees them in order.
        """
        n, hypot = len(p), math.hypot
        stride = n // self._substeps
        for r in self._robots:
            o = r.off
            x0, y0, d = s[o], s[o + 1], r.dist
            i = o // 3  # (x, y) per body, in the snapshot's order
            while i < n:  # not a for over a range: its iterator costs more here (~10 % of the loop)
                x = p[i]
                y = p[i + 1]
                d += hypot(x - x0, y - y0)
                x0 = x
                y0 = y
                i += stride
            r.dist = d

    def _apply_commands(self, s: list[float]) -> None:
        half_dt = self._dt / 2
        cos, sin = math.cos, math.sin
        controls: list[float] = []  # every robot's control body (vx, vy, omega), set in one call below
        for r in self._robots:
            o = r.off
            if r.cmd is not None:
                vx, vy, w = r.twist
                theta = s[o + 2] + half_dt * s[o + 5]
                c, sn = cos(theta), sin(theta)
                controls += (c * vx - sn * vy, sn * vx + c * vy, w)
            else:
                controls += (0.0, 0.0, 0.0)
            holder = self._holder
            if holder is r and not r.dribbler:
                self._release()
                holder = None
            # `_can_capture(r)`, inlined (six robots a tick); a kick that cannot fire falls through to it.
            if (
                r.kick_armed
                and not self._dead
                and self._pin is None
                and (holder is r or (holder is None and self._in_reach(r, s)))
            ):
                self._kick(r, s)
            elif (
                r.dribbler
                and holder is None
                and not self._dead
                and self._pin is None
                and self.tick >= r.catch_from
                and self._in_reach(r, s)
            ):
                self._capture(r, s)
        self._set_controls(controls)

    def _after_tick(self) -> None:
        """End of a tick: a pinned ball put back, the holder checked, the lines watched."""
        s = self._snap
        pin = self._pin
        if pin is not None:
            b = self._ball_off
            if self._holder is not None or math.hypot(s[b] - pin[0], s[b + 1] - pin[1]) > PIN_TOLERANCE:
                self.place_ball(*pin)
                s = self._fresh()
        if self._holder is not None:
            self._check_holder(self._holder, s)
        self._line_events(s)
