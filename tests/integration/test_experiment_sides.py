"""An experiment's team settings follow the strategy across the swap of ends, end to end: the
swapped match's digest is `arena match --config` of the configuration the row names, whose
parameters are under team b."""

from __future__ import annotations

import json
import subprocess

from tests.integration.helpers import ARENA, arena_json

TEAM_PARAMETER = """
seeds = 1

[base]
home = "AD"
away = "BS"
half_time = 4.0

[factors]
"params.a.kick_speed" = [3.0]
"""


def test_a_team_parameter_is_played_by_its_strategy_at_both_ends(tmp_path):
    f = tmp_path / "side.toml"
    f.write_text(TEAM_PARAMETER)
    out = tmp_path / "out"
    r = subprocess.run([*ARENA, "experiment", "run", str(f), "--out", str(out), "--jobs", "1", "--json"],
                       capture_output=True, text=True, timeout=600)  # fmt: skip
    assert r.returncode == 0, r.stderr[-3000:]
    rows = {row["team"]: row for row in json.loads((out / "rows.json").read_text())}
    assert rows["a"]["config"] == "cells/c000.toml" and rows["b"]["config"] == "cells/c000-ends-swapped.toml"
    for team, row in rows.items():
        assert (row["team_a"], row["team_b"]) == (
            ("advance-dynamic", "basic-static") if team == "a" else ("basic-static", "advance-dynamic")
        )
        m = arena_json(
            "match", "--config", str(out / row["config"]), "--seed", "0",
            "--home", row["team_a"], "--away", row["team_b"], "--engine", "inprocess",
        )  # fmt: skip
        assert m["digest"] == row["digest"], team
        assert m["params"] == {team: {"kick_speed": 3.0}}, m["params"]
