"""One module per process kind, all shaped the same: a `Node` subclass whose
`loop()` holds the logic; argument parsing stays in arena/cli.py."""

from __future__ import annotations

from importlib import import_module

# kind -> (module, class). Imported lazily: a robot never loads pymunk.
NODES = {
    "engine": ("arena.processes.engine", "EngineNode"),
    "referee": ("arena.processes.referee", "RefereeNode"),
    "basestation": ("arena.processes.basestation", "BaseStationNode"),
    "robot": ("arena.processes.robot", "RobotNode"),
    "recorder": ("arena.processes.recorder", "RecorderNode"),
}


def node_class(kind: str):
    module, cls = NODES[kind]
    return getattr(import_module(module), cls)
