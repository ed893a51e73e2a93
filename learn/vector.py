"""`SoccerVectorEnv`: N `SoccerEnv`s in N worker processes, stepped through shared memory.

Gymnasium's `AsyncVectorEnv` pickles every step's command, info dict and
result through a pipe and merges the infos in the parent: measured on the
2-core host, about 330 us of CPU per env step on top of the 350 us of the step
itself (`arena bench learn`). Here each worker reads its action from, and
writes its observation, reward and flags into, arrays in shared memory; the
pipe carries one byte each way per step. An episode that ends is reset in the
same step (Gymnasium's `AutoresetMode.SAME_STEP`): the observation returned is
the next episode's first, the last one is in `infos["final_obs"]` (rows where
`infos["_final_obs"]` is true). Worker i plays seeds seed + i, then the next
seed of its own env at every autoreset, with the options of the last `reset`
(`{"scenario": PATH}`: every episode of that scenario, a curriculum step).
Flat `Box` observations only.
"""

from __future__ import annotations

import multiprocessing as mp
import pickle
import struct
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from arena.learn.single import SoccerEnv

_RESET, _STEP, _CLOSE = b"r", b"s", b"c"


def _arrays(buffers: dict[str, Any], n: int, obs_dim: int, act_shape: tuple[int, ...], act_dtype) -> dict:
    return {
        "obs": np.frombuffer(buffers["obs"], np.float32).reshape(n, obs_dim),
        "final": np.frombuffer(buffers["final"], np.float32).reshape(n, obs_dim),
        "act": np.frombuffer(buffers["act"], act_dtype).reshape(n, *act_shape),
        "rew": np.frombuffer(buffers["rew"], np.float64),
        "flags": np.frombuffer(buffers["flags"], np.uint8).reshape(n, 3),  # terminated, truncated, ended
    }


def _worker(i: int, conn, buffers, n: int, obs_dim: int, act_shape, act_dtype, options: dict) -> None:
    a = _arrays(buffers, n, obs_dim, act_shape, act_dtype)
    env = SoccerEnv(**options)
    reset_options = None
    try:
        while True:
            msg = conn.recv_bytes()
            if msg[:1] == _STEP:
                obs, rew, term, trunc, _ = env.step(a["act"][i])
                a["rew"][i] = rew
                a["flags"][i] = (term, trunc, term or trunc)
                if term or trunc:
                    a["final"][i] = obs
                    obs, _ = env.reset(options=reset_options)
                a["obs"][i] = obs
            elif msg[:1] == _RESET:
                (seed,) = struct.unpack("<q", msg[1:9])
                reset_options = pickle.loads(msg[9:])
                obs, _ = env.reset(seed=None if seed < 0 else seed, options=reset_options)
                a["obs"][i] = obs
            else:
                conn.send_bytes(b"k")
                return
            conn.send_bytes(b"k")
    except Exception as exc:  # the parent raises it, naming the worker
        conn.send_bytes(b"e" + f"{type(exc).__name__}: {exc}".encode())


class SoccerVectorEnv(VectorEnv):
    metadata = {"autoreset_mode": AutoresetMode.SAME_STEP}

    def __init__(self, num_envs: int, **options: Any):
        if num_envs < 1:
            raise ValueError(f"num_envs must be at least 1, got {num_envs}")
        probe = SoccerEnv(**options)
        if len(probe.observation_space.shape or ()) != 1:
            raise ValueError("SoccerVectorEnv takes flat observations (obs='flat'); use AsyncVectorEnv for dicts")
        self.num_envs = n = num_envs
        self.single_observation_space = probe.observation_space
        self.single_action_space = probe.action_space
        self.observation_space = batch_space(probe.observation_space, n)
        self.action_space = batch_space(probe.action_space, n)
        obs_dim = probe.observation_space.shape[0]
        act_shape = probe.action_space.shape or ()
        act_dtype = np.dtype(probe.action_space.dtype)
        ctx = mp.get_context("fork")
        size = int(np.prod(act_shape)) if act_shape else 1
        buffers = {
            "obs": ctx.RawArray("b", 4 * n * obs_dim),
            "final": ctx.RawArray("b", 4 * n * obs_dim),
            "act": ctx.RawArray("b", act_dtype.itemsize * n * size),
            "rew": ctx.RawArray("b", 8 * n),
            "flags": ctx.RawArray("b", 3 * n),
        }
        self._a = _arrays(buffers, n, obs_dim, act_shape, act_dtype)
        self._conns = []
        self.processes = []
        for i in range(n):
            parent, child = ctx.Pipe()
            p = ctx.Process(
                target=_worker,
                args=(i, child, buffers, n, obs_dim, act_shape, act_dtype, options),
                name=f"soccer-env-{i}",
                daemon=True,
            )
            p.start()
            child.close()
            self._conns.append(parent)
            self.processes.append(p)
        self.closed = False

    def _all(self, msg: bytes | list[bytes]) -> None:
        for i, c in enumerate(self._conns):
            c.send_bytes(msg[i] if isinstance(msg, list) else msg)
        for i, c in enumerate(self._conns):
            got = c.recv_bytes()
            if got != b"k":
                raise RuntimeError(f"soccer env worker {i} failed: {got[1:].decode()}")

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None):
        """Every worker's env, seeded seed + i; `options` (e.g. {"scenario": PATH}) hold for its autoresets too."""
        if seed is None:
            seeds = [-1] * self.num_envs
        elif isinstance(seed, int):
            seeds = [seed + i for i in range(self.num_envs)]
        else:
            seeds = [-1 if s is None else s for s in seed]
        opts = pickle.dumps(options)
        self._all([_RESET + struct.pack("<q", s) + opts for s in seeds])
        return self._a["obs"].copy(), {}

    def step(self, actions):
        a = self._a
        a["act"][:] = actions
        self._all(_STEP)
        flags = a["flags"]
        infos: dict[str, Any] = {}
        ended = flags[:, 2].astype(bool)
        if ended.any():
            infos = {"final_obs": a["final"].copy(), "_final_obs": ended}
        return a["obs"].copy(), a["rew"].copy(), flags[:, 0].astype(bool), flags[:, 1].astype(bool), infos

    def close_extras(self, **kwargs: Any) -> None:
        for c, p in zip(self._conns, self.processes):
            try:
                c.send_bytes(_CLOSE)
                c.recv_bytes()
            except (BrokenPipeError, EOFError, OSError):
                pass
            p.join(timeout=5)
            if p.is_alive():
                p.terminate()
