"""Stable-Baselines3 on the shared-memory workers: the adapter's conventions, PPO training, and the
export of docs/learning.md from the trained policy to an ONNX file that `arena match` plays."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tests.integration.helpers import arena_json

try:
    import stable_baselines3  # noqa: F401
except ImportError:
    pytest.skip("Stable-Baselines3 is not installed: pip install 'soccer-arena[sb3]'", allow_module_level=True)

from arena.learn import GoalReward, save_policy
from arena.learn.sb3 import SB3VecEnv

OPTS = dict(robot="a/1", home="BS", away="BS", half_time=0.5, frame_skip=5)  # 11 steps an episode


def test_the_adapter_keeps_sb3s_conventions():
    env = SB3VecEnv(2, **OPTS)
    try:
        env.seed(3)
        obs = env.reset()
        seeds = [i["seed"] for i in env.reset_infos]
        assert obs.shape == (2, 69) and seeds[0] != seeds[1]
        ends = []
        for _ in range(12):
            obs, rew, dones, infos = env.step(np.zeros((2, 4), np.float32))
            ends += [info for info in infos if "terminal_observation" in info]
        assert len(ends) == 2 and all(e["TimeLimit.truncated"] and e["episode"]["l"] == 11 for e in ends)
        assert {e["episode"]["seed"] for e in ends} == set(seeds)
    finally:
        env.close()


@pytest.mark.slow
def test_ppo_trains_on_the_workers_and_its_export_plays_as_a_policy_file(tmp_path):
    import onnx
    import torch
    from stable_baselines3 import PPO

    env = SB3VecEnv(2, reward=GoalReward(progress=0.2), **OPTS)
    try:
        model = PPO("MlpPolicy", env, n_steps=256, batch_size=128, n_epochs=2, seed=0, device="cpu")
        model.learn(total_timesteps=3072)
        assert model.num_timesteps >= 3072 and len(model.ep_info_buffer) >= 100
    finally:
        env.close()

    class Deterministic(torch.nn.Module):  # docs/learning.md's export
        def __init__(self, policy):
            super().__init__()
            self.policy = policy

        def forward(self, obs):
            return torch.clamp(self.policy(obs, deterministic=True)[0], -1.0, 1.0)

    size = model.observation_space.shape[0]
    with warnings.catch_warnings():  # torch's TorchScript exporter warns (deprecation, tracer) as it goes
        warnings.simplefilter("ignore")
        torch.onnx.export(
            Deterministic(model.policy),
            torch.zeros(1, size),
            str(tmp_path / "ppo.onnx"),
            input_names=["obs"],
            output_names=["action"],
            opset_version=17,
            dynamo=False,
        )
    path = save_policy(tmp_path / "attacker.onnx", {1: onnx.load(str(tmp_path / "ppo.onnx"))}, base="BS", frame_skip=5)
    for engine in ("inprocess", "processes"):
        got = arena_json("match", "--home", f"policy:{path}", "--away", "BS", "--half-time", "1", "--engine", engine)
        assert got["ticks"] == 100
