"""Strategy parameters in experiment files: per team, for both teams (params.*), checked at load."""

from __future__ import annotations

import pytest

from arena.config import ConfigError
from arena.experiments import design


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


def _row(cell, gf, ga, r1=10.0, r2=5.0):
    return {"cell": cell, "status": "ok", "goals_for": gf, "goals_against": ga, "coverage_r1": r1, "coverage_r2": r2}


def test_a_round_robin_per_setting_gives_table_2(tmp_path):
    from arena.experiments import experiment_standings

    path = _file(tmp_path, 'home = ["AD", "BS"]\n"timing.perception_latency" = [0, 3]\n')
    exp = design.load(path)
    # cells: c000 AD L0, c001 AD L3, c002 BS L0, c003 BS L3; one seed, both ends: two matches a setting
    rows = [_row("c000", 2, 0), _row("c000", 1, 1), _row("c002", 0, 2, 9.0, 6.0), _row("c002", 1, 1, 9.0, 6.0)]
    rows += [_row("c001", 0, 1), _row("c001", 0, 0), _row("c003", 1, 0), _row("c003", 0, 0)]
    got = experiment_standings.build(exp, rows)
    by = {s["setting"]["timing.perception_latency"]: s for s in got}
    assert by[0]["order"] == "AD > BS" and by[3]["order"] == "BS > AD"
    ad = by[0]["standings"][0]
    assert (ad["W"], ad["D"], ad["L"], ad["GF"], ad["GA"], ad["P"], ad["coverage_ratio"]) == (1, 1, 0, 3, 1, 4, 2.0)
    assert by[0]["standings"][1]["coverage_ratio"] == 1.5
    assert by[0]["matches"] == 2 and by[0]["goals_per_match"] == 2.0
    tied = experiment_standings.build(exp, [_row("c000", 0, 0), _row("c002", 0, 0)])
    assert tied[0]["order"] == "AD = BS"
    assert experiment_standings.plot(got, tmp_path / "plots").stat().st_size > 0


def test_no_round_robin_no_standings(tmp_path):
    from arena.experiments import experiment_standings

    exp = design.load(_file(tmp_path, '"timing.perception_latency" = [0, 3]\n'))
    assert experiment_standings.build(exp, []) == [] and experiment_standings.markdown([]) == []


def test_a_team_parameter_follows_its_strategy_when_the_ends_swap(tmp_path):
    """params.a is the row's strategy's: on the swapped match that strategy is team b, and so are its
    parameters; params.b (the opponent's) moves to team a with it."""
    exp = design.load(_file(tmp_path, 'home = ["AD"]\n"params.a.block_gain" = [2.0]\n"params.b.keeper_gain" = [1.5]\n'))
    for m in exp.matches():
        cfg = exp.match_config(m)
        mine, theirs = ("a", "b") if m["team"] == "a" else ("b", "a")
        assert getattr(cfg, {"a": "home", "b": "away"}[mine]) == "advance-dynamic"
        assert cfg.params == {mine: {"block_gain": 2.0}, theirs: {"keeper_gain": 1.5}}, m
    assert exp.configs[0].params == {"a": {"block_gain": 2.0}, "b": {"keeper_gain": 1.5}}  # the cell as written


def test_a_round_robin_shares_a_match_only_when_the_parameters_agree(tmp_path):
    """AD with kick_speed 3 against AS (AD team a) is not AS with kick_speed 3 against AD (AS team b): the
    parameter is another strategy's there, so the two rows play two matches."""
    from arena.experiments.experiment import Run, RunOptions

    path = tmp_path / "e.toml"
    path.write_text(
        'seeds = 1\nopponents = ["AD", "AS"]\n[base]\nhalf_time = 5.0\n'
        '[factors]\nhome = ["AD", "AS"]\n"params.a.kick_speed" = [3.0]\n'
    )
    exp = design.load(str(path))
    groups = Run(exp, RunOptions(out=tmp_path / "out", progress=False), path.read_text()).todo()
    assert len(exp.matches()) == 4 and len(groups) == 4
    for g in groups:
        cfg = exp.match_config(g[0])
        mine = g[0]["team"]
        assert cfg.params == {mine: {"kick_speed": 3.0}}
