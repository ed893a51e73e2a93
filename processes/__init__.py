"""The process kinds and nothing else: one module per kind (engine, referee,
basestation, robot, recorder, refbox, viewer), all shaped the same: a `Node` subclass with its
wiring, `act` and its loops, or for the two that watch from outside the lockstep (`OBSERVERS`)
an `Observer` with its `observe`; argument parsing stays in arena/commands/. The
library they use lives below: `arena.sim`, `arena.rules`, `arena.recording`,
`arena.strategies`, `arena.runtime`, `arena.schemas`. Only the packages above it
(arena.match and up) import this package."""

from __future__ import annotations

from importlib import import_module

# kind -> (module, class). Imported lazily: a robot never loads pymunk.
NODES = {
    "engine": ("arena.processes.engine", "EngineNode"),
    "referee": ("arena.processes.referee", "RefereeNode"),
    "basestation": ("arena.processes.basestation", "BaseStationNode"),
    "robot": ("arena.processes.robot", "RobotNode"),
    "recorder": ("arena.processes.recorder", "RecorderNode"),
    "refbox": ("arena.processes.refbox", "RefboxNode"),
    "viewer": ("arena.processes.viewer", "ViewerNode"),
}
OBSERVERS = frozenset(("recorder", "viewer"))  # `Observer`s: in nobody's lockstep, no driver


def node_class(kind: str):
    module, cls = NODES[kind]
    return getattr(import_module(module), cls)
