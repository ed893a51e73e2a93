"""`arena bench throughput --rsoccer PYTHON`: the interpreter's VSS-v0 figure beside our match.

rSoccer itself needs Python 3.10 and is not installed here; a stand-in `gym` with a `VSS-v0`
(a double, in a unit test) runs the very script the benchmark hands the interpreter."""

from __future__ import annotations

import os
import sys

import pytest

from arena.config import ConfigError, MatchConfig
from arena.experiments import rsoccer

GYM = """
import time
class _Space:
    def sample(self):
        return [0.0] * 6
class _Env:
    action_space = _Space()
    unwrapped = property(lambda self: self)
    def reset(self):
        self.n = 0
    def step(self, action):
        self.n += 1
        t = time.process_time()
        while time.process_time() - t < 0.0005:
            pass
        return None, 0.0, self.n % 50 == 0, {}
def make(name):
    assert name == "VSS-v0", name
    return _Env()
"""


@pytest.fixture
def fake_python(tmp_path):
    (tmp_path / "gym.py").write_text(GYM)
    (tmp_path / "rsoccer_gym.py").write_text("")
    exe = tmp_path / "python"
    exe.write_text(f'#!/bin/sh\nPYTHONPATH={tmp_path} exec {sys.executable} "$@"\n')
    exe.chmod(0o755)
    return str(exe)


def test_the_script_runs_in_the_named_interpreter_and_is_timed_by_its_cpu(fake_python):
    rate = rsoccer.vss_rate(fake_python, 200)
    assert 200 < rate < 2100  # each stand-in step burns 0.5 ms of CPU: at most 2,000 steps per CPU-second


def test_beside_alternates_and_reports_the_pairs_ratio(fake_python):
    said = []
    got = rsoccer.beside(MatchConfig(half_time=1.0), 2, "BS", fake_python, said.append)
    assert len(got["all_runs"]["vss"]) == len(got["all_runs"]["ours"]) == 2
    assert got["ours_over_vss"] > 0 and got["vss_steps_per_cpu_s"] > 0 and got["ours_ticks_per_cpu_s"] > 0
    assert said[0].startswith("rSoccer run 1/2: VSS-v0 for 101 steps")


def test_an_interpreter_without_rsoccer_is_told_in_one_line(tmp_path):
    bare = tmp_path / "python"  # no site-packages: no gym
    bare.write_text(f'#!/bin/sh\nexec {sys.executable} -I -S "$@"\n')
    bare.chmod(0o755)
    with pytest.raises(ConfigError, match=r"VSS-v0 did not run there: ModuleNotFoundError: No module named 'gym'"):
        rsoccer.check(str(bare))


def test_a_file_that_is_not_an_interpreter_is_told(tmp_path):
    f = tmp_path / "python"
    f.write_text("not a program")
    os.chmod(f, 0o644)
    with pytest.raises(ConfigError, match="cannot run it: Permission denied"):
        rsoccer.check(str(f))
