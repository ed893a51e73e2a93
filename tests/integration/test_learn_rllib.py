"""RLlib's PPO trains SoccerParallelEnv's agents on a local Ray instance, its env runner an actor
(examples/learn_rllib/ppo.py, docs/learning.md)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).parents[2] / "examples" / "learn_rllib" / "ppo.py"


@pytest.mark.slow
def test_rllib_ppo_trains_the_parallel_env_on_a_local_ray_instance():
    for module, extra in (("ray.rllib", "rllib"), ("torch", "sb3")):
        try:
            __import__(module)
        except ImportError:
            pytest.skip(f"{module} is not installed: pip install 'soccer-arena[{extra}]'")
    r = subprocess.run(
        [sys.executable, str(EXAMPLE), "--iterations", "2", "--half-time", "2", "--runners", "1"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    lines = [json.loads(x) for x in r.stdout.splitlines() if x.startswith("{")]
    assert [x["iteration"] for x in lines] == [1, 2]
    assert lines[1]["env_steps"] > lines[0]["env_steps"] > 0
