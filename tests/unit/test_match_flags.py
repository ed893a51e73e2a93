"""One place turns flags into a MatchConfig (arena/commands/_match_flags.py `match_config`), for
every command that plays matches, each with its own defaults; a match process is handed the config itself."""

from __future__ import annotations

import pytest

from arena.cli import parser
from arena.commands._match_flags import match_config
from arena.config import ConfigError, MatchConfig, TimingParams


def config(*argv: str, seed: bool = True) -> MatchConfig:
    return match_config(parser().parse_args(list(argv)), seed=seed)


def test_every_command_gets_the_same_match_from_the_same_flags():
    want = MatchConfig(half_time=20.0, robots=2, link="wifi", timing=TimingParams(perception_latency=1))
    flags = ["--half-time", "20", "--robots", "2", "--link", "wifi", "--perception-latency", "1"]
    assert config("match", "--home", "BS", "--away", "BS", *flags).replace(home=want.home, away=want.away) == want
    assert config("tournament", *flags, "--seed", "99", seed=False) == want  # a tournament's seed is not a match's
    assert config("bench", "match", *flags[:6], seed=False) == want.replace(timing=TimingParams())


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["tournament", "--robots", "9"], "--robots must be between 1 and 6"),
        (["facts", "--half-time", "1e9"], "at most 3600 s per half"),
        (["bench", "record", "--half-time", "0.001"], "shorter than one tick"),
        (["tournament", "--link-param", "wifi.latency_ms"], "bad link override"),
        (["facts", "--perception-latency", "99"], "--perception-latency must be 0..25 ticks"),
    ],
)
def test_each_range_is_the_configurations(argv, needle):
    with pytest.raises(ConfigError, match=needle):
        config(*argv, seed=False)


def test_a_command_s_own_defaults_lie_under_the_file_and_the_flags(tmp_path):
    facts = config("facts", seed=False)
    assert (facts.half_time, facts.home, facts.away) == (60.0, "chase", "chase")
    assert config("tournament", seed=False).half_time == 300.0 and config("bench", "match", seed=False).half_time == 60
    path = tmp_path / "m.toml"
    path.write_text("half_time = 10.0\n[rules]\nkickoff_time = 0.5\n")
    from_file = config("facts", "--config", str(path), seed=False)
    assert (from_file.half_time, from_file.home, from_file.rules.kickoff_time) == (10.0, "chase", 0.5)
    assert config("facts", "--config", str(path), "--half-time", "5", seed=False).half_time == 5.0
    assert config("tournament", "--config", str(path), seed=False).rules.kickoff_time == 0.5


def test_a_match_process_is_handed_the_whole_configuration():
    """`python -m arena.match` (match/child.py) gets every field, rules and field included."""
    import dataclasses

    from arena.match import child, play

    cfg = config("match", "--home", "AD", "--away", "BS", "--half-time", "2", "--seed", "41", "--robots", "2")
    cfg = cfg.replace(rules=dataclasses.replace(cfg.rules, kickoff_time=0.5))
    cfg = cfg.replace(field=dataclasses.replace(cfg.field, runoff=cfg.field.runoff + 0.25))
    proc, given = child.start(cfg, "inprocess")
    out, _ = proc.communicate(input=given, timeout=120)
    assert proc.returncode == 0
    result = child.decode(out)
    assert result.digest == play(cfg).digest != play(cfg.replace(rules=MatchConfig().rules)).digest
