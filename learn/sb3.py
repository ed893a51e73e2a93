"""`SB3VecEnv`: Stable-Baselines3's `VecEnv` over `SoccerVectorEnv`'s shared-memory workers.

    from stable_baselines3 import PPO
    from arena.learn.sb3 import SB3VecEnv

    env = SB3VecEnv(4, robot="a/1", home="AD", away="BS", frame_skip=5)
    PPO("MlpPolicy", env).learn(100_000)

SB3's conventions: an episode that ends is reset in the same step, its last observation in
`infos[i]["terminal_observation"]`, `TimeLimit.truncated` when the match ran out rather than ended;
`infos[i]["episode"]` carries the episode's return `r` and length `l` (what SB3 logs as ep_rew_mean
and ep_len_mean) with its `seed`, `score`, `ticks` and `scenario` verdict. `env.seed(s)` (or PPO's
`seed=`) makes the next reset draw every worker's seeds from s (arena.learn.vector). Needs the `sb3`
extra: pip install 'soccer-arena[sb3]'.
"""

from __future__ import annotations

from typing import Any

import numpy as np

try:
    from stable_baselines3.common.vec_env import VecEnv
except ImportError:
    raise ImportError("arena.learn.sb3 needs Stable-Baselines3: pip install 'soccer-arena[sb3]'") from None

from arena.learn.vector import SoccerVectorEnv


class SB3VecEnv(VecEnv):
    def __init__(self, num_envs: int, **options: Any):
        self.venv = SoccerVectorEnv(num_envs, autoreset_mode="SameStep", **options)
        self.render_mode = None
        self._actions: np.ndarray | None = None
        super().__init__(num_envs, self.venv.single_observation_space, self.venv.single_action_space)

    def reset(self):
        root = self._seeds[0]  # seed(s) sets s + i for worker i; one root gives every worker its own stream
        options = self._options[0] or None
        obs, infos = self.venv.reset(seed=root, options=options)
        self.reset_infos = [{"seed": int(s)} for s in infos["seed"]]
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self):
        obs, rewards, term, trunc, info = self.venv.step(self._actions)
        dones = term | trunc
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for i in np.flatnonzero(dones):
            ep = info["episode"]
            infos[i] = {
                "terminal_observation": info["final_obs"][i],
                "TimeLimit.truncated": bool(trunc[i] and not term[i]),
                "episode": {
                    "r": float(ep["r"][i]),
                    "l": int(ep["l"][i]),
                    "seed": int(ep["seed"][i]),
                    "score": tuple(int(x) for x in ep["score"][i]),
                    "ticks": int(ep["ticks"][i]),
                    "scenario": ep["scenario"][i],
                },
            }
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        n = len(list(self._get_indices(indices)))
        if attr_name == "render_mode":
            return [None] * n
        raise AttributeError(f"SB3VecEnv's workers do not share attribute {attr_name!r}")

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        raise AttributeError(f"SB3VecEnv's workers take no attribute {attr_name!r} (pass it as an option)")

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list[Any]:
        raise AttributeError(f"SB3VecEnv's workers have no method {method_name!r} to call from here")

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False] * len(list(self._get_indices(indices)))
