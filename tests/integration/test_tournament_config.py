"""A tournament holds one base configuration and every match gets all of it: a `rules` value
from `--config FILE` reaches the tournament's matches on the processes engine (each handed its
whole `MatchConfig`, no flags), and their digests are those of `arena match --config FILE`."""

from __future__ import annotations

import json

from tests.integration.helpers import arena_json

RULES = "[rules]\nkickoff_time = 0.5\n"  # START half a second earlier: every digest differs from the default's


def test_a_rules_value_of_the_base_configuration_reaches_every_match(tmp_path):
    path = tmp_path / "match.toml"
    path.write_text(RULES)
    out = tmp_path / "t"
    common = ("--half-time", "2")
    summary = arena_json(
        "tournament", "--strategies", "BS,AD", "--legs", "1", "--jobs", "1", "--config", str(path), *common,
        "--out", str(out),
    )  # fmt: skip
    (played,) = summary["matches"]
    assert played["status"] == "ok" and played["engine"] == "processes"
    pairing = ("--home", played["home"], "--away", played["away"], "--seed", str(played["seed"]), *common)
    with_file = arena_json("match", "--config", str(path), *pairing, "--engine", "inprocess")
    without = arena_json("match", *pairing, "--engine", "inprocess")
    assert played["digest"] == with_file["digest"] != without["digest"]
    settings = json.loads((out / "settings.json").read_text())
    assert settings["config"] == {"rules": {"kickoff_time": 0.5}}, "--resume compares it"
