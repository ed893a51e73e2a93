"""`SoccerVectorEnv`: N `SoccerEnv`s in N worker processes, stepped through shared memory.

Gymnasium's `AsyncVectorEnv` pickles every step's command, info dict and
result through a pipe and merges the infos in the parent: measured on the
2-core host, about 330 us of CPU per env step on top of the 350 us of the step
itself (`arena bench learn`). Here each worker reads its action from, and
writes its observation, reward and flags into, arrays in shared memory; the
pipe carries one byte each way per step, and an episode's summary when one ends.

Autoreset, as Gymnasium names its modes: `NEXT_STEP` (the default there, and
here; what its vector wrappers take): the step that ends an episode returns its
last observation, and the next step resets that worker (its action ignored,
reward 0) and returns the new episode's first; `SAME_STEP`: the ending step
returns the new episode's first observation, the last one in
`infos["final_obs"]` (rows where `infos["_final_obs"]` is true).

Seeds: `reset(seed=s)` spawns one `numpy.random.SeedSequence` child of s per
worker, and every episode of worker i draws its match seed from child i's own
stream, so no two workers (and no two episodes, but with the odds of a 63-bit
collision) play the same match; `reset()` without a seed spawns them from fresh
entropy. The seed each episode plays is in the infos (`infos["seed"]`, rows
`infos["_seed"]`, at every reset), and an ending episode's summary in
`infos["episode"]` (rows `infos["_episode"]`): `r` its return, `l` its steps,
`seed`, `score` (a, b), `ticks`, and `scenario` (the verdict, or None). Flat
`Box` observations only.
"""

from __future__ import annotations

import multiprocessing as mp
import pickle
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from arena.learn.parallel import episode_seed
from arena.learn.single import SoccerEnv

_RESET, _STEP, _CLOSE = b"r", b"s", b"c"
_OK, _ENDED = b"k", b"i"


def _arrays(buffers: dict[str, Any], n: int, obs_dim: int, act_shape: tuple[int, ...], act_dtype) -> dict:
    return {
        "obs": np.frombuffer(buffers["obs"], np.float32).reshape(n, obs_dim),
        "final": np.frombuffer(buffers["final"], np.float32).reshape(n, obs_dim),
        "act": np.frombuffer(buffers["act"], act_dtype).reshape(n, *act_shape),
        "rew": np.frombuffer(buffers["rew"], np.float64),
        "seed": np.frombuffer(buffers["seed"], np.int64),
        "flags": np.frombuffer(buffers["flags"], np.uint8).reshape(n, 4),  # terminated, truncated, ended, reset
    }


class _Worker:
    """One worker process's env, its seed stream and its episode so far."""

    def __init__(self, i: int, a: dict, options: dict, same_step: bool):
        self.i, self.a, self.same_step = i, a, same_step
        self.env = SoccerEnv(**options)
        self.stream: np.random.SeedSequence | None = None
        self.reset_options: dict | None = None
        self.pending = False  # NEXT_STEP: the episode ended; the next step resets
        self.ret, self.steps = 0.0, 0

    def reset(self, seed: int | None = None) -> None:
        if seed is None:
            seed = episode_seed(self.stream)
        obs, _ = self.env.reset(seed=seed, options=self.reset_options)
        i, a = self.i, self.a
        a["obs"][i] = obs
        a["seed"][i] = seed
        a["flags"][i, 3] = 1
        self.pending, self.ret, self.steps = False, 0.0, 0

    def step(self) -> bytes:
        i, a = self.i, self.a
        a["flags"][i] = 0
        if self.pending:
            a["rew"][i] = 0.0
            self.reset()
            return _OK
        obs, rew, term, trunc, info = self.env.step(a["act"][i])
        self.ret += rew
        self.steps += 1
        a["rew"][i] = rew
        a["flags"][i, :3] = (term, trunc, term or trunc)
        if not (term or trunc):
            a["obs"][i] = obs
            return _OK
        summary = {
            "r": self.ret,
            "l": self.steps,
            "seed": info["seed"],
            "score": tuple(info["score"]),
            "ticks": info["tick"],
            "scenario": info.get("scenario"),
        }
        if self.same_step:
            a["final"][i] = obs
            self.reset()
        else:
            a["obs"][i] = obs
            self.pending = True
        return _ENDED + pickle.dumps(summary)


def _worker(i: int, conn, buffers, n: int, obs_dim: int, act_shape, act_dtype, options: dict, same_step) -> None:
    w = None
    try:
        w = _Worker(i, _arrays(buffers, n, obs_dim, act_shape, act_dtype), options, same_step)
        while True:
            msg = conn.recv_bytes()
            if msg[:1] == _STEP:
                conn.send_bytes(w.step())
            elif msg[:1] == _RESET:
                start, w.reset_options = pickle.loads(msg[1:])  # from the parent: our own bytes
                if isinstance(start, np.random.SeedSequence):
                    w.stream = start
                    w.reset()
                else:  # an explicit seed for this worker: it plays it, then its own stream of it
                    w.stream = np.random.SeedSequence(start)
                    w.reset(seed=start)
                conn.send_bytes(_OK)
            else:
                conn.send_bytes(_OK)
                return
    except Exception as exc:  # the parent raises it, naming the worker
        conn.send_bytes(b"e" + f"{type(exc).__name__}: {exc}".encode())


class SoccerVectorEnv(VectorEnv):
    def __init__(self, num_envs: int, autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP, **options: Any):
        if num_envs < 1:
            raise ValueError(f"num_envs must be at least 1, got {num_envs}")
        mode = AutoresetMode(autoreset_mode)
        if mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise ValueError(f"autoreset_mode must be NEXT_STEP or SAME_STEP, got {mode}")
        self.metadata = {"autoreset_mode": mode, "render_modes": []}
        self.same_step = mode == AutoresetMode.SAME_STEP
        probe = SoccerEnv(**options)
        if len(probe.observation_space.shape or ()) != 1:
            raise ValueError("SoccerVectorEnv takes flat observations (obs='flat'); use AsyncVectorEnv for dicts")
        self.spec = probe.spec
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
            "seed": ctx.RawArray("b", 8 * n),
            "flags": ctx.RawArray("b", 4 * n),
        }
        self._a = _arrays(buffers, n, obs_dim, act_shape, act_dtype)
        self._conns = []
        self.processes = []
        for i in range(n):
            parent, child = ctx.Pipe()
            p = ctx.Process(
                target=_worker,
                args=(i, child, buffers, n, obs_dim, act_shape, act_dtype, options, self.same_step),
                name=f"soccer-env-{i}",
                daemon=True,
            )
            p.start()
            child.close()
            self._conns.append(parent)
            self.processes.append(p)
        self.closed = False

    def _all(self, msg: bytes | list[bytes]) -> list[dict | None]:
        """Send each worker its message; the episode summary each sent back (None: none ended)."""
        for i, c in enumerate(self._conns):
            c.send_bytes(msg[i] if isinstance(msg, list) else msg)
        ended: list[dict | None] = [None] * self.num_envs
        for i, c in enumerate(self._conns):
            got = c.recv_bytes()
            if got[:1] == _ENDED:
                ended[i] = pickle.loads(got[1:])  # our own worker's bytes
            elif got != _OK:
                raise RuntimeError(f"soccer env worker {i} failed: {got[1:].decode()}")
        return ended

    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        """Every worker's env. `seed` s: worker i's episodes draw from the i-th SeedSequence child of s (fresh
        entropy when None); a list: worker i plays seed[i] first. `options` (e.g. {"scenario": PATH}) hold
        for its autoresets too. The infos say the seed each worker plays (`seed`, `_seed`)."""
        if isinstance(seed, list | tuple):
            if len(seed) != self.num_envs:
                raise ValueError(f"{len(seed)} seeds for {self.num_envs} workers")
            fresh = np.random.SeedSequence().spawn(self.num_envs)
            starts = [fresh[i] if s is None else int(s) for i, s in enumerate(seed)]
        else:
            starts = np.random.SeedSequence(seed).spawn(self.num_envs)
        self._all([_RESET + pickle.dumps((s, options)) for s in starts])
        self._a["flags"][:] = 0
        return self._a["obs"].copy(), {"seed": self._a["seed"].copy(), "_seed": np.ones(self.num_envs, bool)}

    def step(self, actions):
        a = self._a
        a["act"][:] = actions
        ended = self._all(_STEP)
        flags = a["flags"]
        infos: dict[str, Any] = {}
        if flags[:, 3].any():
            infos["seed"], infos["_seed"] = a["seed"].copy(), flags[:, 3].astype(bool)
        mask = flags[:, 2].astype(bool)
        if mask.any():
            infos["episode"] = self._episodes(ended)
            infos["_episode"] = mask
            if self.same_step:
                infos["final_obs"], infos["_final_obs"] = a["final"].copy(), mask
        return a["obs"].copy(), a["rew"].copy(), flags[:, 0].astype(bool), flags[:, 1].astype(bool), infos

    def _episodes(self, ended: list[dict | None]) -> dict[str, np.ndarray]:
        n = self.num_envs
        out = {
            "r": np.zeros(n),
            "l": np.zeros(n, np.int64),
            "seed": np.zeros(n, np.int64),
            "ticks": np.zeros(n, np.int64),
            "score": np.zeros((n, 2), np.int64),
            "scenario": np.full(n, None, dtype=object),
        }
        for i, e in enumerate(ended):
            if e is not None:
                for k, v in e.items():
                    out[k][i] = v
        return out

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
