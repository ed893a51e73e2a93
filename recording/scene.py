"""The Foxglove-viewable layer of a match recording (docs/recording.md).

Foxglove decodes neither msgpack nor CBOR, so next to the raw msgpack channels
the recorder writes two protobuf channels with their schemas embedded, built
with foxglove-sdk's message types:

* `/scene` (`foxglove.SceneUpdate`), from the ground-truth `world` frames: the
  field (grass, lines, fence, goals), one cube per robot coloured by team
  (MSL colours: team a cyan, team b magenta) with a heading arrow and a label
  "a/1 attacker", the ball as a sphere, and the score and clock as text. The
  field entity is part of every update, so a seek in Foxglove always shows it.
* `/referee_log` (`foxglove.Log`): every referee command, every engine ball
  event and the score after each goal.

Everything here is a pure function of the frames and the configuration, so the
layer is as deterministic as the match.
"""

from __future__ import annotations

import math

from foxglove.messages import (
    ArrowPrimitive,
    Color,
    CubePrimitive,
    LinePrimitive,
    LinePrimitiveLineType,
    Log,
    LogLevel,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    SpherePrimitive,
    TextPrimitive,
    Timestamp,
    Vector3,
)

from arena.config import MatchConfig
from arena.schemas.messages import EngineEvents, Referee, World

SCENE_TOPIC = "/scene"
LOG_TOPIC = "/referee_log"
FRAME = "field"  # Foxglove frame id of the field frame (docs/field.md)

TEAM_COLOURS = {"a": (0.0, 0.75, 1.0), "b": (1.0, 0.1, 0.75)}  # MSL cyan and magenta
GRASS = Color(r=0.13, g=0.45, b=0.17, a=1.0)
WHITE = Color(r=1.0, g=1.0, b=1.0, a=1.0)
FENCE = Color(r=0.5, g=0.5, b=0.5, a=1.0)
NET = Color(r=0.9, g=0.9, b=0.9, a=0.25)
BALL = Color(r=1.0, g=0.55, b=0.0, a=1.0)
TEXT = Color(r=1.0, g=1.0, b=1.0, a=1.0)
CIRCLE_SEGMENTS = 48  # [-] polyline segments of the centre circle
POST = 0.1  # [m] goal post and crossbar thickness
LABEL_SIZE = 0.3  # [m] robot label font size
SCORE_SIZE = 0.6  # [m] score text font size


def stamp(ns: int) -> Timestamp:
    return Timestamp(sec=ns // 1_000_000_000, nsec=ns % 1_000_000_000)


def _yaw(theta: float) -> Quaternion:
    return Quaternion(x=0.0, y=0.0, z=math.sin(theta / 2.0), w=math.cos(theta / 2.0))


IDENTITY = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)


def _pose(x: float, y: float, z: float, theta: float = 0.0) -> Pose:
    return Pose(position=Vector3(x=x, y=y, z=z), orientation=_yaw(theta) if theta else IDENTITY)


def _colour(team: str, alpha: float = 1.0) -> Color:
    r, g, b = TEAM_COLOURS.get(team, (0.8, 0.8, 0.8))
    return Color(r=r, g=g, b=b, a=alpha)


def _line(points: list[tuple[float, float]], kind: LinePrimitiveLineType, width: float, colour: Color) -> LinePrimitive:
    return LinePrimitive(
        type=kind,
        pose=_pose(0.0, 0.0, 0.005),
        thickness=width,
        points=[Point3(x=x, y=y, z=0.0) for x, y in points],
        color=colour,
    )


def _rect(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def field_primitives(cfg: MatchConfig) -> tuple[list[CubePrimitive], list[LinePrimitive]]:
    """Grass, lines, fence and goals in the field frame (numbers: docs/field.md)."""
    f = cfg.field
    hl, hw = f.length / 2.0, f.width / 2.0
    lw = f.line_width
    loop, strip = LinePrimitiveLineType.LineLoop, LinePrimitiveLineType.LineStrip
    cubes = [
        CubePrimitive(
            pose=_pose(0.0, 0.0, -0.011),
            size=Vector3(x=f.length + 2 * f.runoff, y=f.width + 2 * f.runoff, z=0.02),
            color=GRASS,
        )
    ]
    circle = [
        (f.center_circle_radius * math.cos(a), f.center_circle_radius * math.sin(a))
        for a in (2.0 * math.pi * i / CIRCLE_SEGMENTS for i in range(CIRCLE_SEGMENTS))
    ]
    lines = [
        _line(_rect(-hl, -hw, hl, hw), loop, lw, WHITE),
        _line([(0.0, -hw), (0.0, hw)], strip, lw, WHITE),
        _line(circle, loop, lw, WHITE),
        _line(_rect(-hl - f.runoff, -hw - f.runoff, hl + f.runoff, hw + f.runoff), loop, 0.05, FENCE),
    ]
    for side in (-1.0, 1.0):
        gx = side * hl
        for depth, width in ((f.penalty_area_depth, f.penalty_area_width), (f.goal_area_depth, f.goal_area_width)):
            ix = gx - side * depth
            lines.append(
                _line([(gx, -width / 2), (ix, -width / 2), (ix, width / 2), (gx, width / 2)], strip, lw, WHITE)
            )
        mark = gx - side * f.penalty_mark_distance
        cubes.append(CubePrimitive(pose=_pose(mark, 0.0, 0.0), size=Vector3(x=lw, y=lw, z=0.01), color=WHITE))
        # goal: two posts, the crossbar and a translucent net
        back = gx + side * f.goal_depth / 2.0
        for py in (-f.goal_width / 2.0 - POST / 2.0, f.goal_width / 2.0 + POST / 2.0):
            cubes.append(
                CubePrimitive(
                    pose=_pose(gx, py, f.goal_height / 2.0), size=Vector3(x=POST, y=POST, z=f.goal_height), color=WHITE
                )
            )
        cubes.append(
            CubePrimitive(
                pose=_pose(gx, 0.0, f.goal_height),
                size=Vector3(x=POST, y=f.goal_width + 2 * POST, z=POST),
                color=WHITE,
            )
        )
        cubes.append(
            CubePrimitive(
                pose=_pose(back, 0.0, f.goal_height / 2.0),
                size=Vector3(x=f.goal_depth, y=f.goal_width, z=f.goal_height),
                color=NET,
            )
        )
    return cubes, lines


class SceneBuilder:
    """World frames in, `SceneUpdate` payloads out; keeps the latest roles and score."""

    def __init__(self, cfg: MatchConfig):
        self.cfg = cfg
        self._field_cubes, self._field_lines = field_primitives(cfg)
        self.roles: dict[tuple[str, int], str] = {}
        self.score = (0, 0)
        self.stage = "PRE_GAME"
        # built once: the parts of every update that never change
        r = cfg.robot
        self._body = Vector3(x=r.size, y=r.size, z=r.height)
        self._colours = {team: _colour(team) for team in TEAM_COLOURS}
        rb = cfg.ball.radius
        self._ball = Vector3(x=2 * rb, y=2 * rb, z=2 * rb)

    def update(self, world: World, ns: int, extra: list[SceneEntity] | None = None) -> bytes:
        """One `SceneUpdate`: field, robots, ball, score and clock; `extra` entities appended (a viewer's)."""
        ts = stamp(ns)
        size, height = self.cfg.robot.size, self.cfg.robot.height
        entities = [
            SceneEntity(timestamp=ts, frame_id=FRAME, id="field", cubes=self._field_cubes, lines=self._field_lines)
        ]
        for r in world.robots:
            role = self.roles.get((r.team, r.robot), "")
            label = f"{r.team}/{r.robot} {role}".strip()
            heading = _yaw(r.theta)
            entities.append(
                SceneEntity(
                    timestamp=ts,
                    frame_id=FRAME,
                    id=f"robot/{r.team}/{r.robot}",
                    cubes=[
                        CubePrimitive(
                            pose=Pose(position=Vector3(x=r.x, y=r.y, z=height / 2.0), orientation=heading),
                            size=self._body,
                            color=self._colours.get(r.team),
                        )
                    ],
                    arrows=[
                        ArrowPrimitive(
                            pose=Pose(position=Vector3(x=r.x, y=r.y, z=height + 0.05), orientation=heading),
                            shaft_length=size * 0.6,
                            shaft_diameter=0.05,
                            head_length=0.15,
                            head_diameter=0.12,
                            color=WHITE,
                        )
                    ],
                    texts=[
                        TextPrimitive(
                            pose=_pose(r.x, r.y, height + 0.35),
                            billboard=True,
                            font_size=LABEL_SIZE,
                            color=TEXT,
                            text=label,
                        )
                    ],
                )
            )
        rb = self.cfg.ball.radius
        entities.append(
            SceneEntity(
                timestamp=ts,
                frame_id=FRAME,
                id="ball",
                spheres=[
                    SpherePrimitive(
                        pose=_pose(world.ball_x, world.ball_y, world.ball_z + rb),
                        size=self._ball,
                        color=BALL,
                    )
                ],
            )
        )
        a, b = self.score
        f = self.cfg.field
        entities.append(
            SceneEntity(
                timestamp=ts,
                frame_id=FRAME,
                id="score",
                texts=[
                    TextPrimitive(
                        pose=_pose(0.0, f.width / 2.0 + f.runoff + 0.6, 0.5),
                        billboard=True,
                        font_size=SCORE_SIZE,
                        color=TEXT,
                        text=f"a {a} : {b} b   {self.stage}   {world.t:.1f} s",
                    )
                ],
            )
        )
        if extra:
            entities.extend(extra)
        return SceneUpdate(entities=entities).encode()

    def beliefs(
        self, ns: int, seen: dict[tuple[str, int], tuple[float, float]], fused: dict[str, tuple[float, float, float]]
    ) -> list[SceneEntity]:
        """What the teams believe, drawn faintly: each robot's perceived ball (a small
        translucent sphere in its team colour) and each base station's fused P_ball (a larger one)."""
        ts = stamp(ns)
        rb = self.cfg.ball.radius
        out = []
        for (team, n), (x, y) in sorted(seen.items()):
            out.append(
                SceneEntity(
                    timestamp=ts,
                    frame_id=FRAME,
                    id=f"seen/{team}/{n}",
                    spheres=[SpherePrimitive(pose=_pose(x, y, rb), size=self._ball, color=_colour(team, 0.35))],
                )
            )
        big = Vector3(x=4 * rb, y=4 * rb, z=4 * rb)
        for team, (x, y, z) in sorted(fused.items()):
            out.append(
                SceneEntity(
                    timestamp=ts,
                    frame_id=FRAME,
                    id=f"p_ball/{team}",
                    spheres=[SpherePrimitive(pose=_pose(x, y, z + rb), size=big, color=_colour(team, 0.2))],
                    texts=[
                        TextPrimitive(
                            pose=_pose(x, y, z + 4 * rb + 0.1),
                            billboard=True,
                            font_size=LABEL_SIZE * 0.6,
                            color=_colour(team, 0.6),
                            text=f"P_ball {team}",
                        )
                    ],
                )
            )
        return out

    def referee_log(self, ref: Referee, ns: int) -> list[bytes]:
        """One Log per command issued; the score rides on GOAL lines. Updates the score text."""
        self.score = (ref.score_a, ref.score_b)
        self.stage = ref.stage
        out = []
        for c in ref.commands:
            text = f"{c.name} {c.team}".strip()
            if c.name == "GOAL":
                text += f": score {ref.score_a}:{ref.score_b}"
            elif c.name in ("DROP_BALL", "KICKOFF"):
                text += f" at ({c.x:.2f}, {c.y:.2f})"
            level = LogLevel.Warning if c.name == "GOAL" else LogLevel.Info
            out.append(Log(timestamp=stamp(ns), level=level, message=text, name="referee").encode())
        return out

    def events_log(self, frame: EngineEvents, ns: int) -> list[bytes]:
        out = []
        for ev in frame.events:
            who = f" {ev.team}/{ev.robot}" if ev.robot >= 0 else (f" {ev.team}" if ev.team else "")
            text = f"{ev.kind}{who} at ({ev.x:.2f}, {ev.y:.2f}), tick {ev.tick}"
            level = LogLevel.Error if ev.kind == "ROBOT_DEAD" else LogLevel.Debug
            out.append(Log(timestamp=stamp(ns), level=level, message=text, name="engine").encode())
        return out


def schema(kind: str):
    """The foxglove-sdk schema (name, encoding "protobuf", FileDescriptorSet) of a layer topic."""
    return SceneUpdate.get_schema() if kind == SCENE_TOPIC else Log.get_schema()
