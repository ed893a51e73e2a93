"""arena.learn: the PettingZoo and Gymnasium conformance suites, determinism, deployment as a strategy."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test, parallel_seed_test

from arena.learn import SoccerEnv, SoccerParallelEnv, make_vector_env
from arena.match.inprocess import play_in_process
from arena.runtime.config import ConfigError, MatchConfig
from arena.strategies import registry

SHORT = dict(home="AD", away="BS", half_time=0.6)  # 61 ticks: fast, and the kick-off is played


def test_parallel_api_test_passes_for_both_observation_and_action_forms():
    parallel_api_test(SoccerParallelEnv(agents=["a/1", "b/2"], **SHORT), num_cycles=70)
    parallel_api_test(SoccerParallelEnv(agents=["b/0"], obs="dict", actions="discrete", frame_skip=4, **SHORT))


def test_parallel_seed_test_passes():
    parallel_seed_test(lambda: SoccerParallelEnv(agents=["a/1", "a/2"], **SHORT), num_cycles=20)


def test_gymnasium_check_env_passes():
    check_env(SoccerEnv("a/1", **SHORT), skip_render_check=True)
    check_env(SoccerEnv("b/1", obs="dict", actions="discrete", **SHORT), skip_render_check=True)


def play(env, seed: int, actions_seed: int = 0) -> tuple[dict, list]:
    rng = np.random.default_rng(actions_seed)
    obs, _ = env.reset(seed=seed)
    seen = []
    acts = {a: np.zeros(4, np.float32) for a in env.agents}  # one array per agent, rewritten every step
    while env.agents:
        for a in env.agents:
            acts[a][:] = rng.uniform(-1, 1, 4)
        obs, *_ = env.step(acts)
        seen.append(np.concatenate([obs[a] for a in sorted(obs)]))
    return env.digests(), seen


def test_the_same_seed_and_actions_give_the_same_digests_twice():
    env = SoccerParallelEnv(agents=["a/1", "b/1"], home="AD", away="BS", half_time=1.0, end_on_goal=False)
    d1, o1 = play(env, seed=5)
    d2, o2 = play(env, seed=5)
    for i, (x, y) in enumerate(zip(o1, o2)):
        assert np.array_equal(x, y), f"observations differ first at step {i}"
    assert d1 == d2 and len(d1) == 10
    d3, _ = play(env, seed=5, actions_seed=1)
    assert d3["robot/a/1"] != d1["robot/a/1"], "other actions, another match"


def test_an_episodes_actions_replayed_as_a_policy_strategy_give_the_envs_digests(tmp_path):
    """The in-process engine with the recorded actions as the strategy `policy:PATH` (the distributed
    match: tests/integration/test_learn_deploy.py)."""
    env = SoccerParallelEnv(agents=["a/1", "a/2"], home="AD", away="BS", half_time=1.0, end_on_goal=False, frame_skip=3)
    digests, _ = play(env, seed=8)
    path = env.save_actions("a", tmp_path / "actions.pkl")
    cfg = MatchConfig(seed=8, home=registry.resolve_name(f"policy:{path}"), away="basic-static", half_time=1.0)
    summaries, _ = play_in_process(cfg, watch=())
    assert {name: s.digest for name, s in summaries.items()} == digests


def test_a_missing_policy_file_is_one_line():
    with pytest.raises(ConfigError, match="policy file /nonexistent.pkl not found"):
        registry.resolve_name("policy:/nonexistent.pkl")


def test_frame_skip_holds_the_action_and_the_episode_follows_the_match():
    env = SoccerParallelEnv(agents=["a/1"], home="BS", away="BS", half_time=0.5, frame_skip=4, end_on_goal=False)
    env.reset(seed=1)
    steps = 0
    while env.agents:
        _, _, term, trunc, info = env.step({"a/1": np.zeros(4, np.float32)})
        steps += 1
    assert steps == -(-(env.cfg.total_ticks + 1) // 4) and trunc["a/1"] and not term["a/1"]
    half = SoccerParallelEnv(agents=["a/1"], home="BS", away="BS", half_time=0.5, until="half", end_on_goal=False)
    half.reset(seed=1)
    n = 0
    while half.agents:
        half.step({"a/1": np.zeros(4, np.float32)})
        n += 1
    assert n == half.cfg.half_ticks


def test_bad_agents_are_refused():
    for agents in (["a/3"], ["a/1", "robot/a/1"], ["referee"], []):
        with pytest.raises(ValueError):
            SoccerParallelEnv(agents=agents)


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ({"obs": "pixels"}, "obs must be flat or dict, got 'pixels'"),
        ({"actions": "x"}, "actions must be box or discrete, got 'x'"),
        ({"until": "goal"}, "until must be match or half, got 'goal'"),
    ],
)
def test_a_bad_option_is_named_with_its_value(option, message):
    with pytest.raises(ValueError, match=f"^{message}$"):  # one message named all three options, not which
        SoccerParallelEnv(**option)


def test_the_vector_env_steps_its_workers_with_their_own_seeds():
    venv = make_vector_env(2, asynchronous=False, robot="a/1", **SHORT)
    obs, infos = venv.reset(seed=4)
    assert obs.shape == (2, 69) and list(infos["seed"]) == [4, 5]
    obs, rew, term, trunc, _ = venv.step(np.zeros((2, 4), np.float32))
    assert obs.shape == (2, 69) and rew.shape == (2,)
    venv.close()


def test_the_vector_env_in_worker_processes_plays_what_the_envs_play_here():
    """Two workers through shared memory against two SoccerEnvs in this process, autoresets included."""
    opts = dict(robot="a/1", home="AD", away="BS", half_time=0.3)
    venv = make_vector_env(2, **opts)
    here = [SoccerEnv(**opts) for _ in range(2)]
    try:
        obs, _ = venv.reset(seed=4)
        for i, env in enumerate(here):
            assert np.array_equal(obs[i], env.reset(seed=4 + i)[0])
        rng = np.random.default_rng(0)
        ends = 0
        for t in range(70):  # 31 steps an episode: two autoresets each
            act = rng.uniform(-1, 1, (2, 4)).astype(np.float32)
            obs, rew, term, trunc, info = venv.step(act)
            for i, env in enumerate(here):
                o, r, te, tr, _ = env.step(act[i])
                if te or tr:
                    ends += 1
                    assert info["_final_obs"][i] and np.array_equal(info["final_obs"][i], o), f"step {t}"
                    o, _ = env.reset()
                assert np.array_equal(obs[i], o) and (rew[i], term[i], trunc[i]) == (r, te, tr), f"step {t}, env {i}"
        assert ends == 4
    finally:
        venv.close()
    assert not any(p.is_alive() for p in venv.processes)


def test_without_the_extra_the_import_names_it_in_one_line():
    code = "import sys; sys.modules['pettingzoo'] = None; import arena.learn"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    assert r.stderr.strip().splitlines()[-1] == (
        "ImportError: arena.learn needs the learn extra: pip install 'soccer-arena[learn]'"
    )


def test_docs_learning_md_lists_every_observation_part_and_discrete_action():
    from pathlib import Path

    from arena.strategies.learned import DISCRETE, obs_fields

    doc = (Path(__file__).parents[2] / "docs" / "learning.md").read_text()
    for name, n, lo, hi, text in obs_fields(3):
        assert f"| `{name}` | {n} | [{lo:g}, {hi:g}] | {text} |" in doc, name
    for i, (name, a) in enumerate(DISCRETE):
        assert f"| {i} | {name} | {', '.join(f'{x:g}' for x in a)} |" in doc, name


def test_a_tournament_names_a_policy_files_matches_by_its_file_name():
    from arena.experiments.fixtures import Fixture

    fx = Fixture(3, "policy:/runs/x/keeper.pkl", "advance-dynamic", 2, "policy:/runs/x/keeper.pkl", "AD", 1)
    assert fx.id == "003-policy-keeper.pkl-AD-leg02"


def test_arena_bench_learn_reports_the_ratios():
    import json

    r = subprocess.run(
        [sys.executable, "-m", "arena", "bench", "learn", "--runs", "1", "--half-time", "0.5", "--json"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["match_ticks_per_cpu_second"] > 0 and out["env1_steps_per_cpu_second"] > 0
    ratio = out["env1_steps_per_cpu_second"] / out["match_ticks_per_cpu_second"]  # of the rounded figures
    assert out["env1_ratio"] == pytest.approx(ratio, abs=0.002)
    assert set(out["vector_ratio"]) == {"1", "5"}


SHOT = """
[[scenario]]
name = "shoot"
time_limit = 3.0
[scenario.play]
robots = 2
[scenario.start.ball]
x = 4.5
y = 0.0
[[scenario.start.robots]]
robot = "a/1"
x = 3.9
y = 0.0
theta = 0.0
[[scenario.start.robots]]
robot = "b/0"
present = false
[[scenario.expect]]
name = "a scores"
kind = "goal"
team = "a"
"""


def test_a_scenario_is_an_episode_judged_at_its_end(tmp_path):
    path = tmp_path / "shoot.scenario.toml"
    path.write_text(SHOT)
    env = SoccerParallelEnv(agents=["a/1"], robots=2, frame_skip=5)
    shoot, wait = np.array([0.6, 0, 0, 1], np.float32), np.zeros(4, np.float32)
    verdicts = {}
    for name, action in (("shoot", shoot), ("wait", wait)):
        obs, info = env.reset(seed=2, options={"scenario": str(path)})
        assert env.match.cfg.total_ticks == 150 and "scenario" not in info["a/1"]
        steps = 0
        while env.agents:
            obs, rew, term, trunc, info = env.step({"a/1": action})
            steps += 1
        verdicts[name] = (info["a/1"]["scenario"]["passed"], term["a/1"], trunc["a/1"], rew["a/1"], steps)
    assert verdicts["shoot"][:4] == (True, True, False, 1.0) and verdicts["shoot"][4] < 30
    assert verdicts["wait"] == (False, False, True, 0.0, 31)
    with pytest.raises(ValueError, match="plays 2 robots a team, this env 3"):
        SoccerParallelEnv(agents=["a/1"]).reset(seed=1, options={"scenario": str(path)})


def test_a_policy_trained_on_two_robots_a_team_plays_a_3v3_match(tmp_path):
    from arena.learn import LinearPolicy, save_policy
    from arena.strategies.learned import obs_fields

    size = sum(n for _, n, *_ in obs_fields(2))
    policy = LinearPolicy(np.zeros((4, size)), np.array([0.5, 0.0, 0.0, 0.0]))
    path = save_policy(tmp_path / "p.pkl", {1: policy}, base="BS", robots=2)
    cfg = MatchConfig(seed=1, home=registry.resolve_name(f"policy:{path}"), away="basic-static", half_time=0.5)
    summaries, _ = play_in_process(cfg, watch=())  # a 69-number observation would fail the 4 x 57 weights
    assert summaries["robot/a/1"].tick == cfg.total_ticks
    assert summaries["engine"].extra["distance_m"]["a/1"] > 0.2  # it drove


def test_the_learning_example_runs(tmp_path):
    import json

    example = Path(__file__).parents[2] / "examples" / "learn_to_score" / "cem.py"
    args = ["--iterations", "1", "--population", "2", "--seeds-per-candidate", "1", "--eval-seeds", "1"]
    r = subprocess.run(
        [sys.executable, str(example), "--out", str(tmp_path), *args], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, r.stderr
    result = json.loads((tmp_path / "results.json").read_text())
    assert set(result) >= {"trained", "untrained", "curve"} and (tmp_path / "learning-curve.png").stat().st_size
    assert registry.resolve_name(f"policy:{tmp_path / 'policy.pkl'}").startswith("policy:/")


PUSH = """
[[scenario]]
name = "push"
time_limit = 3.0
[scenario.play]
robots = 2
[scenario.start.ball]
x = -3.0
y = 2.0
[[scenario.start.robots]]
robot = "a/1"
x = 3.0
y = 0.0
theta = 0.0
"""


def test_a_learner_that_pushes_gets_the_foul(tmp_path):
    path = tmp_path / "push.scenario.toml"
    path.write_text(PUSH)
    seen = []

    def reward(agent, outcome):
        seen.extend((c.name, c.team) for c in outcome.commands)
        return 0.0

    env = SoccerParallelEnv(agents=["a/1"], robots=2, frame_skip=5, reward=reward)
    env.reset(seed=1, options={"scenario": str(path)})
    while env.agents:
        env.step({"a/1": np.array([1.0, 0, 0, 0], np.float32)})
    assert ("FREEKICK", "b") in seen, seen  # it drove into b's keeper


def test_the_vector_envs_autoresets_keep_playing_the_scenario_it_was_reset_to(tmp_path):
    path = tmp_path / "shoot.scenario.toml"
    path.write_text(SHOT)
    venv = make_vector_env(2, robot="a/1", robots=2, frame_skip=5)
    try:
        venv.reset(seed=1, options={"scenario": str(path)})
        shoot = np.tile(np.array([0.6, 0, 0, 1], np.float32), (2, 1))
        goals = 0
        for _ in range(60):  # a goal in under 30 steps each episode: at least two episodes each
            _, rew, term, _, _ = venv.step(shoot)
            goals += int(term.sum())
            assert (rew[term] == 1.0).all()
        assert goals >= 4
    finally:
        venv.close()


def test_a_scenario_episode_ends_once_its_verdict_is_decided(tmp_path):
    """The ball in the penalty area passes `ball_in` early; an expectation broken early fails it early."""
    head = SHOT.split("[[scenario.expect]]")[0].replace("time_limit = 3.0", "time_limit = 10.0")
    cases = {
        "reached": '[[scenario.expect]]\nname = "in the area"\nkind = "ball_in"\nregion = [4.9, -2.5, 6.0, 2.5]\n',
        "broken": '[[scenario.expect]]\nname = "stays out"\nkind = "ball_never_in"\nregion = [4.9, -2.5, 6.0, 2.5]\n',
    }
    for name, expect in cases.items():
        path = tmp_path / f"{name}.scenario.toml"
        path.write_text(head + expect)
        env = SoccerParallelEnv(agents=["a/1"], robots=2, frame_skip=5)
        env.reset(seed=2, options={"scenario": str(path)})
        steps = 0
        while env.agents:
            _, _, term, trunc, info = env.step({"a/1": np.array([0.6, 0, 0, 0], np.float32)})
            steps += 1
        verdict = info["a/1"]["scenario"]
        assert term["a/1"] and not trunc["a/1"] and steps < 40, (name, steps)
        assert verdict["passed"] == (name == "reached") and verdict["decided"]
    plain = SoccerParallelEnv(agents=["a/1"], robots=2, frame_skip=5, end_on_verdict=False)
    plain.reset(seed=2, options={"scenario": str(tmp_path / "reached.scenario.toml")})
    steps = 0
    while plain.agents:
        plain.step({"a/1": np.zeros(4, np.float32)})
        steps += 1
    assert steps == 101  # the whole 10 s
