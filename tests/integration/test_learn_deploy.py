"""An env episode's actions, played by real robot processes over zenoh, give the env's digests."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from tests.integration.helpers import ARENA, arena_json, spawn, wait_for

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from arena.learn import GoalReward, LinearPolicy, MLPPolicy, SoccerParallelEnv, load_policy, save_policy


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
    home = env.save_actions("a", tmp_path / "a.json")
    away = env.save_actions("b", tmp_path / "b.json")
    got = arena_json(
        "match", "--home", f"policy:{home}", "--away", f"policy:{away}", "--half-time", "10", "--seed", "21"
    )
    assert got["engine"] == "processes" and got["ticks"] == 1000
    assert got["process_digests"] == env.digests()


def _trained(env: SoccerParallelEnv, rng) -> LinearPolicy:
    """The best of a few random linear policies on the env's own return: training, at its smallest."""
    size = env.observation_space("a/1").shape[0]
    best, best_return = None, -np.inf
    for _ in range(3):
        candidate = LinearPolicy(rng.normal(0, 0.3, (4, size)), rng.normal(0, 0.3, 4))
        obs, _ = env.reset(seed=int(rng.integers(1000)))
        total = 0.0
        while env.agents:
            obs, rewards, *_ = env.step({a: candidate(obs[a]) for a in env.agents})
            total += sum(rewards.values())
        if total > best_return:
            best, best_return = candidate, total
    return best


def test_a_policy_trained_in_the_env_and_saved_as_onnx_plays_the_envs_digests_on_both_engines(tmp_path):
    """save_policy writes ONNX; the env plays the file's own policies (onnxruntime), and `arena match
    --home policy:FILE.onnx` gives the env's digests, process by process, in-process and over zenoh."""
    pytest.importorskip("onnxruntime")
    opts = {"home": "BS", "away": "AD", "half_time": 3.0, "frame_skip": 2, "end_on_goal": False}
    env = SoccerParallelEnv(agents=["a/1", "a/2"], reward=GoalReward(progress=0.2), **opts)
    rng = np.random.default_rng(11)
    linear = _trained(env, rng)
    size = env.observation_space("a/1").shape[0]
    mlp = MLPPolicy([rng.normal(0, 0.3, (16, size)), rng.normal(0, 0.3, (4, 16))], [np.zeros(16), np.zeros(4)])
    path = save_policy(tmp_path / "team.onnx", {1: linear, 2: mlp}, base="BS", frame_skip=2, robots=3)
    assert path.read_bytes()[:1] == b"\x08"  # an ONNX ModelProto (ir_version first), not a pickle
    played = load_policy(path).policies
    obs, _ = env.reset(seed=4)
    while env.agents:
        obs, *_ = env.step({a: played[int(a[-1])](obs[a]) for a in env.agents})
    for engine in ("inprocess", "processes"):
        got = arena_json(
            *("match", "--home", f"policy:{path}", "--away", "AD", "--half-time", "3", "--seed", "4"),
            *("--engine", engine),
        )
        assert got["process_digests"] == env.digests(), engine


def test_a_robot_started_by_hand_plays_its_own_copy_of_the_policy_file(tmp_path, reap):
    """Hardware in the loop: a/1 runs `arena run robot --policy` with the episode's actions, while the
    match's own file (for the base station) holds another policy: the digests show which one a/1 played."""
    env = SoccerParallelEnv(agents=["a/1"], home="BS", away="BS", half_time=2.0, end_on_goal=False)
    rng = np.random.default_rng(5)
    env.reset(seed=9)
    while env.agents:
        env.step({"a/1": rng.uniform(-1, 1, 4).astype(np.float32)})
    mine = env.save_actions("a", tmp_path / "robot-copy.json")
    size = env.observation_space("a/1").shape[0]
    theirs = save_policy(tmp_path / "launcher.onnx", {1: LinearPolicy(np.zeros((4, size)), np.zeros(4))}, "BS")
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    match = spawn(
        *("match", "--home", f"policy:{theirs}", "--away", "BS", "--half-time", "2", "--seed", "9"),
        *("--external", "a/1", "--match", "hilpolicy", "--listen", endpoint, "--json"),
    )
    reap.append(match)
    wait_for(lambda: match.stderr.readline(), 60, "the launcher's instructions")
    command = match.stderr.readline().split()
    assert command[:3] == ["arena", "run", "robot"]
    robot = subprocess.Popen([*ARENA, *command[1:], "--policy", mine], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    reap.append(robot)
    out, err = match.communicate(timeout=240)
    assert match.returncode == 0, err
    assert robot.wait(timeout=30) == 0
    assert json.loads(out)["process_digests"] == env.digests()
