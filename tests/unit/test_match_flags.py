"""One place turns flags into a MatchConfig (arena/commands/_match_flags.py `match_config`), for
every command that plays matches; the commands that run `arena match` build its argv from a config."""

from __future__ import annotations

import pytest

from arena.cli import parser
from arena.commands._match_flags import match_config
from arena.runtime.config import ConfigError, MatchConfig, TimingParams
from arena.tools.experiments.matches import match_argv


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


def test_the_argv_of_a_config_is_that_config():
    cfg = config(
        "match", "--home", "AD", "--away", "BS", "--half-time", "7.5", "--seed", "41", "--robots", "4",
        "--link", "wifi", "--link-param", "wifi.latency_ms=12.5", "--perception-latency", "2",
    )  # fmt: skip
    argv = match_argv(cfg, "inprocess")
    assert argv[3] == "match" and argv[argv.index("--engine") + 1] == "inprocess" and "--json" in argv
    what = [a for i, a in enumerate(argv) if a not in ("--engine", "inprocess", "--json")]
    assert config(*what[3:]) == cfg
