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

from arena.config import ConfigError, MatchConfig
from arena.learn import SoccerEnv, SoccerParallelEnv, make_vector_env
from arena.match.inprocess import play_in_process
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
    path = env.save_actions("a", tmp_path / "actions.json")
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
        ({"half_time": -1}, r"half_time must be in \(0, 3600\] seconds a half, got -1"),
        ({"robots": 0}, "robots must be 1..6 a team, goalkeeper included, got 0"),
        ({"frame_skip": 0}, "frame_skip must be an integer of at least 1, got 0"),
        ({"render_mode": "human"}, "render_mode must be None or 'rgb_array', got 'human'"),
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


def _replayed(venv, here, mode: str, steps: int) -> int:
    """Step the vector env and, for each worker, a SoccerEnv here on the seeds the infos report; the
    observations, rewards, flags and episode summaries agree. The episodes that ended."""
    obs, infos = venv.reset(seed=4)
    for i, env in enumerate(here):
        assert np.array_equal(obs[i], env.reset(seed=int(infos["seed"][i]))[0])
    rng = np.random.default_rng(0)
    ends, pending, returns = 0, [False] * len(here), [0.0] * len(here)
    for t in range(steps):
        act = rng.uniform(-1, 1, (len(here), 4)).astype(np.float32)
        obs, rew, term, trunc, info = venv.step(act)
        for i, env in enumerate(here):
            if pending[i]:  # NEXT_STEP: this step reset the worker
                assert info["_seed"][i] and (rew[i], term[i], trunc[i]) == (0.0, False, False)
                o = env.reset(seed=int(info["seed"][i]))[0]
                pending[i], returns[i] = False, 0.0
                assert np.array_equal(obs[i], o), f"step {t}, env {i}"
                continue
            o, r, te, tr, inf = env.step(act[i])
            returns[i] += r
            assert (rew[i], term[i], trunc[i]) == (r, te, tr), f"step {t}, env {i}"
            if te or tr:
                ends += 1
                ep = {k: v[i] for k, v in info["episode"].items()}
                assert info["_episode"][i] and ep["seed"] == inf["seed"] and ep["r"] == returns[i]
                assert tuple(ep["score"]) == inf["score"] and ep["ticks"] == inf["tick"] and ep["scenario"] is None
                if mode == "SameStep":
                    assert info["_final_obs"][i] and np.array_equal(info["final_obs"][i], o), f"step {t}"
                    o = env.reset(seed=int(info["seed"][i]))[0]
                    returns[i] = 0.0
                else:
                    pending[i] = True
            assert np.array_equal(obs[i], o), f"step {t}, env {i}"
    return ends


@pytest.mark.parametrize("mode", ["NextStep", "SameStep"])
def test_the_vector_env_in_worker_processes_plays_what_the_envs_play_here(mode):
    """Two workers through shared memory against two SoccerEnvs in this process, autoresets included,
    in both of Gymnasium's autoreset modes."""
    opts = dict(robot="a/1", home="AD", away="BS", half_time=0.3)
    venv = make_vector_env(2, autoreset_mode=mode, **opts)
    try:
        assert _replayed(venv, [SoccerEnv(**opts) for _ in range(2)], mode, 70) == 4  # 31 steps an episode
    finally:
        venv.close()
    assert not any(p.is_alive() for p in venv.processes)


def test_two_workers_never_play_the_same_seed():
    """Each worker draws its episodes' seeds from its own SeedSequence child: no seed twice over many
    autoresets; the same root seed gives the same seeds, none gives fresh ones."""
    venv = make_vector_env(2, robot="a/1", home="BS", away="BS", half_time=0.05, frame_skip=5)  # 2 steps an episode
    try:
        played = []
        for root in (7, 7, None):
            _, infos = venv.reset(seed=root)
            seeds = [list(infos["seed"])]
            for _ in range(40):
                _, _, _, _, info = venv.step(np.zeros((2, 4), np.float32))
                if "seed" in info:
                    seeds.append([s for s, new in zip(info["seed"], info["_seed"]) if new])
            played.append([s for row in seeds for s in row])
        first, again, fresh = played
        assert len(first) >= 30 and len(set(first)) == len(first)  # worker 0's second is not worker 1's first
        assert first == again and not set(first) & set(fresh)
    finally:
        venv.close()


def test_gymnasiums_vector_wrappers_take_the_vector_env():
    from gymnasium.wrappers.vector import FlattenObservation, NormalizeObservation

    venv = NormalizeObservation(FlattenObservation(make_vector_env(2, robot="a/1", **SHORT)))
    try:
        obs, _ = venv.reset(seed=1)
        for _ in range(3):
            obs, *_ = venv.step(np.zeros((2, 4), np.float32))
        assert obs.shape == (2, 69) and np.isfinite(obs).all()
    finally:
        venv.close()


def test_reset_without_a_seed_draws_fresh_entropy_and_says_which_seed_it_played():
    env = SoccerEnv("a/1", **SHORT)
    seeds = {env.reset()[1]["seed"] for _ in range(3)}
    assert len(seeds) == 3 and not seeds & {0, 1, 2, 3}
    env.reset(seed=5)
    after = [env.reset()[1]["seed"] for _ in range(2)]
    env.reset(seed=5)
    assert [env.reset()[1]["seed"] for _ in range(2)] == after  # a seeded run is reproducible


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
    path = save_policy(tmp_path / "p.onnx", {1: policy}, base="BS", robots=2)
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
    assert registry.resolve_name(f"policy:{tmp_path / 'policy.onnx'}").startswith("policy:/")


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


def _returns(tmp_path, y: float, reward) -> tuple[float, float, list]:
    """a/1 shoots the ball from 1.5 m out, on the line y: (its return, the ball's in-play progress, restarts)."""
    path = tmp_path / f"out-{y}.scenario.toml"
    path.write_text(
        SHOT.replace("y = 0.0", f"y = {y}")
        .replace("time_limit = 3.0", "time_limit = 6.0")
        .split("[[scenario.expect]]")[0]
    )
    env = SoccerParallelEnv(agents=["a/1"], robots=2, frame_skip=5, reward=reward, end_on_verdict=False)
    env.reset(seed=2, options={"scenario": str(path)})
    seen = []
    total = progress = 0.0
    while env.agents:
        _, rew, *_ = env.step({"a/1": np.array([0.6, 0, 0, 1], np.float32)})
        total += rew["a/1"]
        outcome = env.last_outcomes["a"]
        progress += outcome.ball_progress
        seen += [("against", r) for r in outcome.restarts_against] + [("for", r) for r in outcome.restarts_for]
    return total, progress, seen


def test_the_default_shaping_pays_nothing_for_kicking_the_ball_out_beside_the_post(tmp_path):
    """The ball played over the goal line beside the post gains in-play progress on its way; the goal kick
    against charges it back, so the documented shaping GoalReward(progress=0.2) earns nothing there, and
    a goal keeps it. The ball's placement for the goal kick is not progress."""
    from arena.learn import GoalReward

    out, gained, seen = _returns(tmp_path, 1.6, GoalReward(progress=0.2))  # the post is at y = 1.0
    assert ("against", "GOALKICK") in seen, seen
    assert gained > 1.0  # the ball went 1.5 m to the line and on: in-play progress it made
    assert out <= 1e-9, out  # ... all of it charged back
    goal, gained_goal, _ = _returns(tmp_path, 0.0, GoalReward(progress=0.2))
    assert goal >= 1.0 + 0.2 * 1.0 and goal > out + 1.0


def test_gymnasium_make_with_rgb_array_passes_check_env_with_its_render_check():
    import gymnasium

    env = gymnasium.make("arena/Soccer-v0", render_mode="rgb_array", **SHORT)
    assert env.spec.max_episode_steps == 61  # 61 ticks, one decision each
    check_env(env.unwrapped)  # the render check included: it makes the env again from its spec
    env.reset(seed=1)
    frame = env.render()
    assert frame.shape == (780, 960, 3) and frame.dtype == np.uint8
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 8  # the field, its lines, robots and the ball


def test_state_is_ground_truth_in_the_attack_frame_and_the_discrete_form_masks_the_kick():
    env = SoccerParallelEnv(agents=["b/1"], actions="discrete", **SHORT)
    obs, infos = env.reset(seed=3)
    mask = infos["b/1"]["action_mask"]
    assert mask.dtype == np.int8 and list(mask) == [1] * 9 + [0]  # no ball held: no kick
    for _ in range(10):
        obs, _, _, _, infos = env.step({"b/1": 1})
    s = env.state()
    assert s.shape == env.state_space.shape and env.state_space.contains(s)
    w = env.match.world()
    b1 = next(r for r in w.robots if r.team == "b" and r.robot == 1)
    half = env.cfg.field.length / 2
    assert s[6 + 8 + 1] == pytest.approx(-b1.x / half * env.match.attack_dir_a, abs=1e-6)  # b/1, after b/0
    assert s[0] == pytest.approx(-w.ball_x / half * env.match.attack_dir_a, abs=1e-6)  # team b attacks -x first


def test_one_agent_may_be_named_by_a_string():
    assert SoccerParallelEnv(agents="a/1", **SHORT).possible_agents == ["a/1"]  # not "a", "/", "1"


@pytest.mark.parametrize(
    ("actions", "form", "message"),
    [
        ({}, "box", r"no action for a/1 \(step\(\) needs one for every agent"),
        ({"a/1": np.zeros(3)}, "box", r"a/1: a box action has shape \(4,\) \(vx, vy, omega, kick\), got \(3,\)"),
        ({"a/1": np.full(4, np.nan)}, "box", "a/1: a box action's numbers must be finite"),
        ({"a/1": np.array([np.inf, 0, 0, 0])}, "box", "a/1: a box action's numbers must be finite"),
        ({"a/1": np.array([1.5, 0, 0, 0])}, "box", r"a/1: a box action's numbers are in \[-1, 1\]"),
        ({"a/1": "fast"}, "box", "a/1: a box action is 4 numbers"),
        ({"a/1": -1}, "discrete", "a/1: a discrete action is one of 0..9, got -1"),
        ({"a/1": 10}, "discrete", "a/1: a discrete action is one of 0..9, got 10"),
        ({"a/1": 2.5}, "discrete", "a/1: a discrete action is one integer 0..9"),
        ({"a/1": np.nan}, "discrete", "a/1: a discrete action is one integer 0..9"),
    ],
)
def test_a_bad_action_is_refused_with_the_agent_named_and_never_played(actions, form, message):
    """A NaN must not play as full reverse, a discrete -1 not as the kick: refused before the match moves."""
    env = SoccerParallelEnv(agents=["a/1"], actions=form, **SHORT)
    env.reset(seed=1)
    tick = env.match.tick
    with pytest.raises(ValueError, match=message):
        env.step(actions)
    assert env.match.tick == tick and env.recorded["a/1"] == []


def test_a_float32_rounding_past_one_is_played_clipped():
    """An exported tanh policy gives -1.0000001 in float32: that is -1, not a bad action."""
    env = SoccerParallelEnv(agents=["a/1"], **SHORT)
    env.reset(seed=1)
    tick = env.match.tick
    env.step({"a/1": np.array([-1.0000001, 1.0000001, 0, 0], np.float32)})
    assert env.match.tick > tick


def test_a_deployed_policy_that_gives_nan_stops_its_robot_with_a_clear_error():
    from arena.strategies.learned import View, to_cmd

    view = View.of(MatchConfig(), "a")
    with pytest.raises(ValueError, match="must be finite"):
        to_cmd(0, np.array([np.nan, 0, 0, 0], np.float32), view)
    with pytest.raises(ValueError, match="one of 0..9, got -1"):
        to_cmd(0, -1, view, discrete=True)
