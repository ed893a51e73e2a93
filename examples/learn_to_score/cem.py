"""Learn to score past a keeper: the cross-entropy method on a linear policy, numpy only.

    python examples/learn_to_score/cem.py --out runs/cem

The task is the scenario score_past_keeper.scenario.toml: robot a/1 starts behind the ball at the
edge of the penalty area, and team b's keeper (basic-static) guards the goal. The policy is
action = tanh(W x + b) on six numbers of the robot's own observation (the ball's and the goal's
position in its body frame, whether it sees and holds the ball), 28 parameters. The cross-entropy
method (Rubinstein 1999; de Boer et al. 2005, Alg. 2) samples a population of parameter vectors from
a Gaussian, plays each on the same seeds, and refits the Gaussian to the best fifth.

It writes into --out: learning-curve.png, policy.onnx (a policy file: `arena match --home
policy:OUT/policy.onnx --away BS` plays it), and results.json with the trained and the untrained
policy's goals over 50 seeds no training episode used.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from arena.learn import LinearPolicy, Outcome, SoccerParallelEnv, obs_fields, save_policy

SCENARIO = Path(__file__).with_name("score_past_keeper.scenario.toml")
ROBOTS = 2  # the scenario's
AGENT = "a/1"
FRAME_SKIP = 5  # 100 ms a step
# (part, index in the part): ball visible, ball forward, ball left, has ball, goal forward, goal left
FEATURES = [("ball", 0), ("ball", 3), ("ball", 4), ("ball", 6), ("goal", 0), ("goal", 1)]


def columns() -> list[int]:
    start, at = 0, {}
    for name, n, *_ in obs_fields(ROBOTS):
        at[name] = start
        start += n
    return [at[part] + i for part, i in FEATURES]


def policy_of(theta: np.ndarray, cols: list[int], size: int) -> LinearPolicy:
    """The linear policy over the whole flat observation: zero weights but on the chosen columns."""
    w = np.zeros((4, size))
    w[:, cols] = theta[:, :-1]
    return LinearPolicy(w, theta[:, -1])


def reward(agent: str, o: Outcome) -> float:
    """+1 a goal, -1 one conceded, and 0.2 per metre the ball came nearer the goal's centre, but not over
    a step in which the referee stopped play or placed the ball (a goal kick moves it without a kick)."""
    shaping = 0.0 if o.commands else 0.2 * o.ball_closing
    return o.goals_for - o.goals_against + shaping


def episode(env: SoccerParallelEnv, policy, seed: int) -> tuple[float, bool]:
    obs, _ = env.reset(seed=seed, options={"scenario": SCENARIO})
    total, info = 0.0, {}
    while env.agents:
        obs, rewards, _, _, infos = env.step({AGENT: policy(obs[AGENT])})
        total += rewards[AGENT]
        info = infos[AGENT]
    return total, info["score"][0] > 0


def evaluate(env, policy, seeds) -> tuple[float, int]:
    results = [episode(env, policy, s) for s in seeds]
    return float(np.mean([r for r, _ in results])), sum(g for _, g in results)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="runs/cem", help="output directory (runs/cem)")
    ap.add_argument("--iterations", type=int, default=15)
    ap.add_argument("--population", type=int, default=24)
    ap.add_argument("--seeds-per-candidate", type=int, default=2)
    ap.add_argument("--eval-seeds", type=int, default=50)
    ap.add_argument("--seed", type=int, default=0, help="the sampler's seed")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    env = SoccerParallelEnv(agents=[AGENT], robots=ROBOTS, frame_skip=FRAME_SKIP, reward=reward)
    cols, size = columns(), env.observation_space(AGENT).shape[0]
    mean = np.zeros((4, len(cols) + 1))
    std = np.full_like(mean, 0.5)
    n_elite = max(2, args.population // 5)
    curve = []
    t0 = time.process_time()
    for it in range(args.iterations):
        seeds = [1000 + it * args.seeds_per_candidate + j for j in range(args.seeds_per_candidate)]
        thetas = mean + std * rng.standard_normal((args.population, *mean.shape))
        scores = np.array([evaluate(env, policy_of(t, cols, size), seeds)[0] for t in thetas])
        elite = thetas[np.argsort(scores)[-n_elite:]]
        mean, std = elite.mean(axis=0), elite.std(axis=0) + 0.02
        at_mean, _ = evaluate(env, policy_of(mean, cols, size), seeds)  # the new mean, on the same seeds
        curve.append(
            {
                "iteration": it + 1,
                "episodes": (it + 1) * args.population * len(seeds),
                "population": float(scores.mean()),
                "elite": float(np.sort(scores)[-n_elite:].mean()),
                "best": float(scores.max()),
                "mean_policy": at_mean,
            }
        )
        print(
            f"iteration {it + 1}: return: population {scores.mean():.3f}, elite {curve[-1]['elite']:.3f}, "
            f"new mean policy {at_mean:.3f} ({time.process_time() - t0:.0f} cpu-s)",
            flush=True,
        )
    trained = policy_of(mean, cols, size)
    untrained = policy_of(np.zeros_like(mean), cols, size)  # where the search started: it stands still
    first_sample = policy_of(np.random.default_rng(args.seed).normal(0, 0.5, mean.shape), cols, size)
    eval_seeds = range(100_000, 100_000 + args.eval_seeds)  # no training episode used these
    result = {"training_cpu_seconds": round(time.process_time() - t0, 1), "eval_seeds": args.eval_seeds}
    for name, pol in (("trained", trained), ("untrained", untrained), ("random_initial", first_sample)):
        ret, goals = evaluate(env, pol, eval_seeds)
        result[name] = {"mean_return": round(ret, 4), "goals": goals}
        print(f"{name}: {goals} goals in {args.eval_seeds} seeds, mean return {ret:.3f}", flush=True)
    result["curve"] = curve
    save_policy(out / "policy.onnx", {1: trained}, base="basic-static", frame_skip=FRAME_SKIP, robots=ROBOTS)
    (out / "results.json").write_text(json.dumps(result, indent=2))
    plot(curve, result, out / "learning-curve.png")
    print(f"wrote {out}/learning-curve.png, {out}/policy.onnx, {out}/results.json")


def plot(curve, result, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = [c["episodes"] for c in curve]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(x, [c["population"] for c in curve], marker="o", label="population (sampled policies), mean")
    ax.plot(x, [c["elite"] for c in curve], marker="s", label="elite (best fifth), mean")
    ax.plot(x, [c["mean_policy"] for c in curve], marker="^", label="the refitted mean policy")
    ax.axhline(result["untrained"]["mean_return"], color="grey", ls="--", label="untrained, 50 held-out seeds")
    ax.axhline(result["trained"]["mean_return"], color="green", ls="--", label="trained, 50 held-out seeds")
    ax.set_xlabel("training episodes")
    ax.set_ylabel("return (goal +1, 0.2 per metre the ball nears the goal)")
    ax.set_title("CEM, linear policy: score from the penalty area's edge past a keeper")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
