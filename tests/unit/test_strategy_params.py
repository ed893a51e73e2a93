"""Strategy parameters: declared by a strategy (`Strategy.params`), set per team (`MatchConfig.params`),
checked at load, reaching the brains, in the result and the digest."""

from __future__ import annotations

import dataclasses
import json
import random

import msgspec
import pytest

from arena.config import ConfigError, MatchConfig
from arena.match import play
from arena.runtime import matchfile
from arena.strategies import conformance, registry
from arena.strategies.base import Param, RobotContext, Strategy, TeamContext, check_values
from arena.strategies.iris import IrisParams, tunable
from tests.unit.test_strategies import _example_plugin


def test_every_iris_parameter_is_a_field_of_iris_params_with_its_default():
    base = IrisParams()
    for advance in (False, True):
        for p in tunable.params_for(advance):
            part, field = tunable.NESTED.get(p.name, ("", p.name))
            assert getattr(getattr(base, part) if part else base, field) == p.default, p.name
    names = {p.name for p in registry.get("BS").params}
    assert "basic_shoot_distance" in names and "block_gain" not in names  # the basic play reads no block gain
    assert "block_gain" in {p.name for p in registry.get("AD").params}
    assert set(tunable.KEEPER) | set(tunable.KICKER) <= names  # the model's unknowns, in all four


def test_tuned_replaces_top_level_and_nested_fields_and_keeps_the_object_with_none():
    base = IrisParams(advance=True)
    assert tunable.tuned(base, {}) is base
    t = tunable.tuned(base, {"kick_speed": 6.0, "keeper_depth": 0.5, "ball_vel_smoothing": 0.2})
    assert (t.kick_speed, t.skills.keeper_depth, t.fusion.vel_smoothing) == (6.0, 0.5, 0.2)
    assert t.advance and t.skills.behind_ball == base.skills.behind_ball


def test_the_brains_play_the_values_their_team_was_given():
    cfg = MatchConfig(home="advance-dynamic", params={"a": {"kick_speed": 5.0, "intercept_min_speed": 1.2}})
    ad = registry.get("AD")
    robot_a = ad.make_robot(RobotContext(cfg=cfg, team="a", n=0, rng=random.Random(0)))
    robot_b = ad.make_robot(RobotContext(cfg=cfg.replace(away="advance-dynamic"), team="b", n=0, rng=random.Random(0)))
    assert robot_a.p.kick_speed == 5.0 and robot_a.p.skills.intercept_min_speed == 1.2
    assert robot_b.p.kick_speed == 8.0  # team b was given nothing
    team = ad.make_team(TeamContext(cfg=cfg, team="a", rng=random.Random(0)))
    assert team.p.kick_speed == 5.0


@pytest.mark.parametrize(
    ("given", "needle"),
    [
        ({"kick_speed": 9.0}, "kick_speed must be in 2..8, got 9.0"),
        ({"kick_speed": "fast"}, "kick_speed must be float, got 'fast'"),
        ({"kick_speed": True}, "kick_speed must be float, got True"),
        ({"kick_sped": 7.0}, "has no parameter 'kick_sped'"),
        ({"kick_speed": float("inf")}, "kick_speed must be finite"),
        ({"navigator": "teleport"}, "navigator must be one of apf, mapf, sfm, f-sfm"),
    ],
)
def test_a_bad_value_is_one_line_naming_the_strategys_parameters(given, needle):
    with pytest.raises(ConfigError) as exc:
        registry.check_params(MatchConfig(home="advance-dynamic", params={"a": given}))
    text = str(exc.value)
    assert needle in text and "\n" not in text
    assert "its parameters: kick_speed (float 2..8 m/s), keeper_depth (float 0.1..1 m)" in text


def test_a_robot_process_refuses_what_the_command_line_would_have():
    """A configuration that reaches a process unchecked (the config queryable) fails when the brain is built."""
    cfg = MatchConfig(home="advance-dynamic", params={"a": {"kick_speed": 99.0}})
    with pytest.raises(ConfigError, match="kick_speed must be in 2..8"):
        registry.get("AD").make_robot(RobotContext(cfg=cfg, team="a", n=1, rng=random.Random(0)))


def test_a_strategy_without_parameters_takes_none():
    with pytest.raises(ConfigError, match="chase has no parameter 'kick_speed'; its parameters: none"):
        registry.check_params(MatchConfig(away="chase", params={"b": {"kick_speed": 7.0}}))


def test_an_int_for_a_float_is_that_float_and_the_config_survives_json():
    cfg = registry.check_params(MatchConfig(home="advance-dynamic", params={"a": {"kick_speed": 7}}))
    assert cfg.params == {"a": {"kick_speed": 7.0}} and type(cfg.params["a"]["kick_speed"]) is float
    back = MatchConfig.from_json(cfg.to_json())
    assert back == cfg and type(back.params["a"]["kick_speed"]) is float
    assert registry.check_params(MatchConfig()) == MatchConfig()


@pytest.mark.parametrize(
    ("params", "needle"),
    [
        ({"c": {"kick_speed": 1.0}}, "'c' is no team"),
        ({"a": {"kick speed": 1.0}}, "is no parameter name"),
        ({"a": {"kick_speed": float("nan")}}, "params.a.kick_speed must be finite"),
    ],
)
def test_the_configuration_checks_the_shape_of_params(params, needle):
    with pytest.raises(ConfigError, match=needle):
        MatchConfig(params=params).validate()


def test_a_match_file_sets_params_per_team(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('home = "AD"\n[params.a]\nkick_speed = 7\nnavigator = "sfm"\n[params.b]\nkeeper_gain = 2.5\n')
    cfg = matchfile.load(str(path))
    assert cfg.params == {"a": {"kick_speed": 7, "navigator": "sfm"}, "b": {"keeper_gain": 2.5}}
    (tmp_path / "again.toml").write_text(matchfile.dump(cfg))
    assert matchfile.load(str(tmp_path / "again.toml")) == cfg
    path.write_text("[params]\nkick_speed = 7\n")
    with pytest.raises(ConfigError, match="params must hold one table per team"):
        matchfile.load(str(path))


@pytest.mark.parametrize(
    ("text", "want"),
    [
        ("a.kick_speed=7.0", ("a", "kick_speed", 7.0)),
        ("b.kick_speed=7", ("b", "kick_speed", 7)),
        ("a.navigator=sfm", ("a", "navigator", "sfm")),
        ('a.navigator="f-sfm"', ("a", "navigator", "f-sfm")),
        ("a.flag=true", ("a", "flag", True)),
    ],
)
def test_param_flag_values_read_as_toml_scalars(text, want):
    assert registry.parse_param(text) == want


def _toy(params: tuple[Param, ...]) -> Strategy:
    base = registry.get("chase")
    return dataclasses.replace(base, params=params)


@pytest.mark.parametrize(
    ("param", "needle"),
    [
        (Param("speed", default=9.0, low=0.0, high=5.0, meaning="m"), "default 9.0 outside 0.0..5.0"),
        (Param("speed", default=1.0, meaning="m"), "a number needs low and high"),
        (Param("bad name", default=1.0, low=0, high=2, meaning="m"), "must be an identifier"),
        (Param("speed", default=1.0, low=0, high=2), "no meaning given"),
        (Param("mode", default="x", choices=("a", "b"), meaning="m"), "default 'x' not in"),
        (Param("speed", default=[1.0], meaning="m"), "is not bool, int, float or str"),  # type: ignore[arg-type]
    ],
)
def test_conformance_refuses_a_bad_declaration(param, needle):
    with pytest.raises(AssertionError, match=needle):
        conformance.check_params(_toy((param,)), MatchConfig())


def test_conformance_refuses_a_strategy_whose_declared_default_changes_its_play():
    """A brain that reads a value given as if it were a change (here: any value halves the speed) fails."""
    base = registry.get("chase")

    class Slow:
        def __init__(self, ctx):
            self.inner = base.make_robot(ctx)
            self.k = 0.5 if ctx.params else 1.0

        def step(self, tick, sense, order):
            c = self.inner.step(tick, sense, order)
            return msgspec.structs.replace(c, vx=c.vx * self.k)

        def report(self, tick, sense):
            return self.inner.report(tick, sense)

    toy = dataclasses.replace(
        base, make_robot=Slow, params=(Param("speed", default=1.0, low=0.0, high=2.0, meaning="m"),)
    )
    with pytest.raises(AssertionError, match="differ with every parameter given its default and with none"):
        conformance.check_params(toy, MatchConfig())


def test_the_example_plugin_declares_and_plays_its_parameters():
    wall = _example_plugin()
    assert [p.name for p in wall.params] == ["spacing", "cruise"]
    assert check_values("wall", wall.params, {"spacing": 1}) == {"spacing": 1.0}
    cfg = MatchConfig(params={"a": {"spacing": 2.0}})
    robot = wall.make_robot(RobotContext(cfg=cfg, team="a", n=1, rng=random.Random(0)))
    assert robot.spacing == 2.0


def test_a_value_given_changes_the_digest_and_none_given_keeps_it():
    cfg = MatchConfig(home="advance-dynamic", away="basic-static", half_time=30.0, seed=1)
    plain = play(cfg)
    defaults = play(cfg.replace(params={"a": {"kick_speed": 8.0, "keeper_gain": 0.0}}))
    slower = play(cfg.replace(params={"a": {"kick_speed": 6.0}}))
    assert defaults.digest == plain.digest  # the defaults, given, play as before
    assert slower.digest != plain.digest
    assert slower.params == {"a": {"kick_speed": 6.0}} and plain.params == {}
    assert json.loads(json.dumps(slower.to_dict()))["params"] == {"a": {"kick_speed": 6.0}}


def test_the_recording_says_which_values_played(tmp_path):
    from mcap.reader import make_reader

    path = tmp_path / "m.mcap"
    cfg = MatchConfig(home="advance-dynamic", half_time=1.0, params={"a": {"kick_speed": 6.5}})
    play(cfg, record=str(path))
    with open(path, "rb") as fh:
        configs = [json.loads(m.metadata["config"]) for m in make_reader(fh).iter_metadata() if "config" in m.metadata]
    assert configs and configs[0]["params"] == {"a": {"kick_speed": 6.5}}
