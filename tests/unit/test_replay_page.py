"""The HTML replay stays within its size budget: a 2 x 300 s match in well under 5 MB."""

from __future__ import annotations

import math
import re

import msgspec

from arena.config import MatchConfig
from arena.recording.reader import Recording
from arena.review.replay_page import write_page
from arena.schemas.messages import RefCommand, Referee, RobotState, World


def test_a_full_match_page_is_under_the_5_mb_budget(tmp_path):
    cfg = MatchConfig(half_time=300.0)
    enc = msgspec.msgpack.encode
    worlds, refs = [], []
    for k in range(cfg.total_ticks + 1):
        t = k * cfg.timing.dt
        robots = [
            RobotState(team=team, robot=n, x=5.9 * math.sin(t / 7 + n), y=3.9 * math.cos(t / 5 + n), theta=math.sin(t))
            for team in "ab"
            for n in range(3)
        ]
        w = World(tick=k, t=t, ball_x=5.5 * math.sin(t / 3), ball_y=3.5 * math.sin(t / 4), ball_z=0.0, robots=robots)
        worlds.append((k, 0, enc(w)))
        if k % 5 == 0:
            cmds = [RefCommand(name="THROWIN", team="a", tick=k)] if k % 1500 == 0 else []
            refs.append((k, 0, enc(Referee(tick=k, stage="FIRST_HALF", command="START", commands=cmds))))
    rec = Recording("x.mcap", cfg, {}, {"world": worlds, "referee": refs}, {})
    out = write_page(rec, tmp_path / "full.html")
    assert out["frames"] == 6001
    assert out["bytes"] < 5_000_000, out
    text = (tmp_path / "full.html").read_text()
    assert text.count('"THROWIN"') == 21 and not re.search(r"https?://", text)
