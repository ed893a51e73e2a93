"""An env episode's actions, played by real robot processes over zenoh, give the env's digests."""

from __future__ import annotations

import numpy as np
import pytest

from tests.integration.helpers import arena_json

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from arena.learn import SoccerParallelEnv


def test_an_episode_replayed_through_the_distributed_match_gives_the_envs_digests(tmp_path):
    env = SoccerParallelEnv(
        agents=["a/1", "a/2", "b/0"], home="AD", away="BS", half_time=10.0, end_on_goal=False, frame_skip=2
    )
    rng = np.random.default_rng(3)
    env.reset(seed=21)
    steps = 0
    while env.agents:
        env.step({a: rng.uniform(-1, 1, 4).astype(np.float32) for a in env.agents})
        steps += 1
    assert steps == 501  # ticks 0..1000 (2 x 10 s), every second one
    home = env.save_actions("a", tmp_path / "a.pkl")
    away = env.save_actions("b", tmp_path / "b.pkl")
    got = arena_json(
        "match", "--home", f"policy:{home}", "--away", f"policy:{away}", "--half-time", "10", "--seed", "21"
    )
    assert got["engine"] == "processes" and got["ticks"] == 1000
    assert got["process_digests"] == env.digests()
