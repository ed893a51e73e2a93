"""`SoccerEnv`: a Gymnasium env for one robot (every other robot by its team's strategy),
and `make_vector_env`: N of them, each in its own worker process.

`SoccerEnv(robot="a/1", home=..., away=..., **options)` is `SoccerParallelEnv`
with one agent; the options are the same (docs/learning.md). It is registered
as `arena/Soccer-v0`, so `gymnasium.make("arena/Soccer-v0", robot="b/2")` works.
"""

from __future__ import annotations

import dataclasses
from functools import partial
from typing import Any

import gymnasium
from gymnasium.envs.registration import EnvSpec

from arena.learn.parallel import SoccerParallelEnv, agent_name


class SoccerEnv(gymnasium.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 50}

    def __init__(
        self,
        robot: str = "a/1",
        home: str = "advance-dynamic",
        away: str = "basic-static",
        render_mode: str | None = None,
        **options: Any,
    ):
        self.agent = agent_name(robot)
        self.env = SoccerParallelEnv(agents=[self.agent], home=home, away=away, render_mode=render_mode, **options)
        self.render_mode = render_mode
        self.observation_space = self.env.observation_space(self.agent)
        self.action_space = self.env.action_space(self.agent)
        cfg = self.env.cfg
        ticks = cfg.half_ticks if self.env.until == "half" else cfg.total_ticks
        self.max_episode_steps = ticks // self.env.frame_skip + 1  # a whole match's decisions, tick 0 included
        self.metadata = {**self.metadata, "render_fps": round(1 / (cfg.timing.dt * self.env.frame_skip))}
        self._spec: EnvSpec | None = None

    @property
    def spec(self) -> EnvSpec | None:
        """gymnasium.make's spec, with the episode's length in steps (`max_episode_steps`)."""
        return self._spec

    @spec.setter
    def spec(self, value: EnvSpec | None) -> None:
        if value is not None and value.max_episode_steps is None:
            value = dataclasses.replace(value, max_episode_steps=self.max_episode_steps)
        self._spec = value

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        obs, infos = self.env.reset(seed=seed, options=options)
        return obs[self.agent], infos[self.agent]

    def step(self, action: Any):
        a = self.agent
        obs, rewards, terms, truncs, infos = self.env.step({a: action})
        return obs[a], rewards[a], terms[a], truncs[a], infos[a]

    def render(self):
        return self.env.render()

    def state(self):
        return self.env.state()

    def digests(self) -> dict[str, str]:
        return self.env.digests()


def make_vector_env(
    n: int, asynchronous: bool = True, autoreset_mode: str = "NextStep", **options: Any
) -> gymnasium.vector.VectorEnv:
    """`n` `SoccerEnv`s with these options, each in its own worker process (`asynchronous`: a
    `SoccerVectorEnv`, arena.learn.vector), or all in this one (Gymnasium's `SyncVectorEnv`).

    `autoreset_mode`: Gymnasium's `NEXT_STEP` (its default: every vector wrapper takes it) or `SAME_STEP`.
    `reset(seed=s)`: every worker draws its episodes' seeds from its own stream (`SoccerVectorEnv`)."""
    mode = gymnasium.vector.AutoresetMode(autoreset_mode)
    if asynchronous:
        from arena.learn.vector import SoccerVectorEnv

        return SoccerVectorEnv(n, autoreset_mode=mode, **options)
    return gymnasium.vector.SyncVectorEnv([partial(SoccerEnv, **options) for _ in range(n)], autoreset_mode=mode)
