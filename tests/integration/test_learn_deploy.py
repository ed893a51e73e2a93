"""An env episode's actions, played by real robot processes over zenoh, give the env's digests."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from tests.integration.helpers import ARENA, arena_json, spawn, wait_for

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from arena.learn import LinearPolicy, SoccerParallelEnv, save_policy


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


def test_a_robot_started_by_hand_plays_its_own_copy_of_the_policy_file(tmp_path, reap):
    """Hardware in the loop: a/1 runs `arena run robot --policy` with the episode's actions, while the
    match's own file (for the base station) holds another policy: the digests show which one a/1 played."""
    env = SoccerParallelEnv(agents=["a/1"], home="BS", away="BS", half_time=2.0, end_on_goal=False)
    rng = np.random.default_rng(5)
    env.reset(seed=9)
    while env.agents:
        env.step({"a/1": rng.uniform(-1, 1, 4).astype(np.float32)})
    mine = env.save_actions("a", tmp_path / "robot-copy.pkl")
    size = env.observation_space("a/1").shape[0]
    theirs = save_policy(tmp_path / "launcher.pkl", {1: LinearPolicy(np.zeros((4, size)), np.zeros(4))}, "BS")
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
