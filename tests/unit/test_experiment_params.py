"""Strategy parameters in experiment files: per team, for both teams (params.*), checked at load."""

from __future__ import annotations

import pytest

from arena.runtime.config import ConfigError
from arena.tools.experiments import design


def _file(tmp_path, factors: str, extra: str = "") -> str:
    path = tmp_path / "e.toml"
    path.write_text(f'seeds = 1\nopponents = ["AD", "BS"]\n{extra}[base]\nhalf_time = 5.0\n[factors]\n{factors}')
    return str(path)


def test_a_model_parameter_is_set_for_both_teams(tmp_path):
    exp = design.load(_file(tmp_path, 'home = ["AS"]\n"params.*.kick_speed" = [6, 8.0]\n'))
    assert [c.params for c in exp.configs] == [
        {"a": {"kick_speed": 6}, "b": {"kick_speed": 6}},
        {"a": {"kick_speed": 8.0}, "b": {"kick_speed": 8.0}},
    ]
    m = exp.matches()[1]
    assert exp.match_config(m).params["a"]["kick_speed"] == 6  # both ends, both teams


def test_a_team_parameter_is_set_for_that_team_only(tmp_path):
    exp = design.load(_file(tmp_path, 'home = ["AS"]\n"params.a.keeper_gain" = [2.0]\n'))
    assert exp.configs[0].params == {"a": {"keeper_gain": 2.0}}


@pytest.mark.parametrize(
    ("factors", "needle"),
    [
        ('"params.*.kick_speed" = [9.0]', "kick_speed must be in 2..8, got 9.0"),
        ('"params.*.kick_sped" = [7.0]', "has no parameter 'kick_sped'"),
        ('"params.a.block_gain" = [2.0]', "basic-static has no parameter 'block_gain'"),
        ('"params.*" = [1.0]', "give params and 2 keys below it"),
    ],
)
def test_a_bad_parameter_is_said_at_load_naming_the_cell(tmp_path, factors, needle):
    with pytest.raises(ConfigError) as exc:
        design.load(_file(tmp_path, f'home = ["BS"]\n{factors}\n'))
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_the_shipped_table2_study_loads():
    exp = design.load("examples/studies/table2-sensitivity.toml")
    assert {c.home for c in exp.configs} == {"advance-dynamic", "advance-static", "basic-dynamic", "basic-static"}
    assert {(c.params["a"]["kick_speed"], c.timing.perception_latency) for c in exp.configs} == {
        (5.5, 0),
        (5.5, 3),
        (8.0, 0),
        (8.0, 3),
    }
