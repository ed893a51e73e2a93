"""Issue 19: `arena match --config FILE.toml` and `arena config --print`."""

from __future__ import annotations

import subprocess

import pytest

from arena.config import ConfigError, MatchConfig
from arena.runtime import matchfile
from tests.integration.helpers import ARENA, arena_in_process, arena_json


def test_the_printed_defaults_read_back_as_the_defaults(tmp_path, capfd):
    r = arena_in_process(["config", "--print"], capfd)
    assert r.returncode == 0, r.stderr
    path = tmp_path / "match.toml"
    path.write_text(r.stdout)
    assert matchfile.load(str(path)) == MatchConfig()
    assert "length = 12.0  # [m] goal line to goal line" in r.stdout, "keys carry their units"


def test_a_custom_field_size_plays_a_match(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(
        'home = "AD"\naway = "BS"\nhalf_time = 2\n[field]\nlength = 9.0\nwidth = 6.0\npenalty_area_width = 4.0\n'
    )
    small = arena_json("match", "--config", str(path), "--seed", "2")
    assert (small["home"], small["away"], small["half_time"], small["ticks"]) == (
        "advance-dynamic",
        "basic-static",
        2.0,
        200,
    )
    normal = arena_json("match", "--home", "AD", "--away", "BS", "--half-time", "2", "--seed", "2")
    assert small["digest"] != normal["digest"], "the engine played on the file's field"


BAD_KEYS = [
    ("[field]\nlenght = 9\n", "unknown key field.lenght"),
    ('[field]\nlength = "long"\n', "field.length: Expected `float`, got `str`"),
    ("[field]\nlength = -9\n", "field.length must be a finite number >= 0"),
    ("[robot]\nmass = nan\n", "robot.mass must be a finite number"),
    ("colour = 3\n", "unknown key 'colour'"),
    ("[links]\npreset = '5g'\n", "unknown link preset '5g'"),
    ("[links.wifi]\nwarp = 9\n", "unknown link parameter 'warp'"),
    ("half_time = 1e12\n", "--half-time must be at most 3600 s"),
    ("[timing]\nstartup_timeout = -1\n", "timing.startup_timeout"),
    ("[timing]\ndt = 0\n", "timing: dt must be in (0, 0.1] s"),  # was a ZeroDivisionError
    ("[timing]\ndt = nan\n", "timing: dt must be in (0, 0.1] s"),
    ("[timing]\nsubsteps = 100000\n", "substeps in 1..100"),
    ("[timing]\ncomm_period = 0\n", "timing.comm_period must be 1 tick to 1 s (50 ticks of 0.02 s), got 0"),
    ("[timing]\nreferee_period = 100000000\n", "timing.referee_period must be 1 tick to 1 s"),  # no play at all
    ("[field]\nwidth = 1e308\n", "field.width must be at most 100 m"),
    ("[robot]\nwheel_radius = 0\n", "robot.wheel_radius must be > 0"),  # was the engine's LinAlgError
    ("[robot]\nsize = 50\n", "robot.size must be at most 2 m"),
    ("[robot]\nmass = 1e308\n", "robot.mass must be at most 1000 kg, got 1e+308"),  # was played
    ("[rules]\nno_progress_s = inf\n", "rules.no_progress_s must be a finite number"),
    ("[timing]\ndt = 1e-300\n", "timing.dt must be at least 0.0001 s"),  # was astronomically many ticks
    ("a = " + "[" * 3000 + "]" * 3000 + "\n", "nests arrays or tables too deep"),  # was RecursionError
    ("[field\n", "not valid TOML"),
]


@pytest.mark.parametrize(("text", "needle"), BAD_KEYS)
def test_a_bad_key_is_one_line_naming_it(tmp_path, text, needle, capfd):
    """The first case as a real `arena match` process; the others through its entry point in this one."""
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=None) as caught:
        matchfile.load(str(path))
    assert needle in str(caught.value) and str(path) in str(caught.value)
    if (text, needle) == BAD_KEYS[0]:
        r = subprocess.run([*ARENA, "match", "--config", str(path)], capture_output=True, text=True, timeout=60)
    else:
        r = arena_in_process(["match", "--config", str(path)], capfd)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert needle in r.stderr and "Traceback" not in r.stderr
