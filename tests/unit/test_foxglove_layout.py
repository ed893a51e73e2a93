"""The shipped Foxglove layout opens the 3D panel on the viewer's /scene, in the field frame."""

from __future__ import annotations

import json
from pathlib import Path

from arena.processes.viewer import MATCH_TOPIC
from arena.recording.scene import FRAME, LOG_TOPIC, SCENE_TOPIC

LAYOUT = Path(__file__).resolve().parents[2] / "docs" / "foxglove" / "arena-live.json"


def _panels(node) -> list[str]:
    if isinstance(node, str):
        return [node]
    return _panels(node["first"]) + _panels(node["second"])


def test_layout_panels_and_topics():
    layout = json.loads(LAYOUT.read_text())
    panels = _panels(layout["layout"])
    assert sorted(panels) == sorted(layout["configById"])
    three_d = layout["configById"][next(p for p in panels if p.startswith("3D!"))]
    assert three_d["topics"][SCENE_TOPIC]["visible"] is True
    assert three_d["followTf"] == FRAME
    assert 5 <= three_d["cameraState"]["distance"] <= 30
    log = layout["configById"][next(p for p in panels if p.startswith("Log!"))]
    assert log["topicToRender"] == LOG_TOPIC
    raw = layout["configById"][next(p for p in panels if p.startswith("RawMessages!"))]
    assert raw["topicPath"] == MATCH_TOPIC
    assert any(p.startswith("Parameters!") for p in panels)
