"""Learn a 2v2 breakaway: the cross-entropy method on a shared linear policy, numpy only.

    python examples/learn_breakaway/cem.py --out runs/breakaway

The task is the first scenario of breakaway.scenario.toml: team a's robots 1 and 2 start near
midfield with the ball, against team b's basic-static keeper and its one field robot (which
basic-static sends to the ball); 8 s to score. Both learners play one policy, each on its own
observation: action = tanh(W x + b) on six numbers (the ball's and the goal's position in the
robot's body frame, whether it sees and holds the ball), 28 parameters. The reward is the env's
default, GoalReward(): +1 a goal, -1 one conceded, nothing else.

A sparse reward gives the search nothing to rank until some sampled policy scores, so the trainer
starts on the file's easier scenarios (the same play begun nearer the goal) and moves to the next,
harder one once the refitted mean policy scores on half of its round's seeds (--curriculum; the
reward and the opponents are the same in every stage). The cross-entropy method (Rubinstein 1999;
de Boer et al. 2005) samples a population of parameter vectors from a Gaussian, plays each on the
same seeds, and refits the Gaussian to the best fifth. --workers plays candidates in parallel
processes (each with its own env); the result does not depend on their number.

It writes into --out: learning-curve.png, policy.onnx (a policy file: `arena match --home
policy:OUT/policy.onnx --away BS` plays it), results.json with the trained, the untrained and one
randomly drawn policy's goals on --eval-seeds seeds of the task that no training episode used, and
breakaway.scenario.toml, the task with team a played by policy.onnx (`arena scenario run
OUT/breakaway.scenario.toml --seeds 50` judges it on seeds 0..49, which no training episode used either).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import time
from pathlib import Path

import numpy as np

from arena.learn import GoalReward, LinearPolicy, SoccerParallelEnv, obs_fields, save_policy

SCENARIO = Path(__file__).with_name("breakaway.scenario.toml")
TASK = "breakaway from midfield"
CURRICULUM = ["breakaway from the penalty area", "breakaway from 3.5 m out", TASK]  # easiest first
ROBOTS = 3  # the scenario's (a/0 and b/2 are parked)
AGENTS = ["a/1", "a/2"]
FRAME_SKIP = 5  # 100 ms a step
# (part, index in the part): ball visible, ball forward, ball left, has ball, goal forward, goal left
FEATURES = [("ball", 0), ("ball", 3), ("ball", 4), ("ball", 6), ("goal", 0), ("goal", 1)]
EVAL_SEED0 = 100_000  # held-out seeds start here; training seeds are 1000 + ...

_env: SoccerParallelEnv | None = None


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


def make_env() -> SoccerParallelEnv:
    return SoccerParallelEnv(agents=AGENTS, robots=ROBOTS, frame_skip=FRAME_SKIP, reward=GoalReward())


def episode(env: SoccerParallelEnv, policy, seed: int, stage: str) -> tuple[float, bool]:
    """One episode of a scenario; team a's return (both learners get the same reward) and whether it scored."""
    obs, _ = env.reset(seed=seed, options={"scenario": (SCENARIO, stage)})
    total, info = 0.0, {}
    while env.agents:
        obs, rewards, _, _, infos = env.step({a: policy(obs[a]) for a in env.agents})
        total += rewards[AGENTS[0]]
        info = infos[AGENTS[0]]
    return total, info["score"][0] > 0


def evaluate(env, policy, seeds, stage) -> tuple[float, int]:
    results = [episode(env, policy, s, stage) for s in seeds]
    return float(np.mean([r for r, _ in results])), sum(g for _, g in results)


def _play(job) -> tuple[float, int]:
    """A worker's job: one parameter vector on some seeds of one stage, in the worker's own env."""
    global _env
    if _env is None:
        _env = make_env()
    theta, seeds, stage = job
    cols, size = columns(), _env.observation_space(AGENTS[0]).shape[0]
    return evaluate(_env, policy_of(theta, cols, size), seeds, stage)


class Runner:
    """Plays jobs in this process (workers=1) or in a pool of forked workers; same results either way."""

    def __init__(self, workers: int):
        self.pool = multiprocessing.get_context("fork").Pool(workers) if workers > 1 else None

    def map(self, jobs) -> list[tuple[float, int]]:
        return self.pool.map(_play, jobs, chunksize=1) if self.pool else [_play(j) for j in jobs]

    def cpu_seconds(self) -> float:
        """CPU time of this process and its finished children; workers are counted once joined."""
        t = __import__("os").times()
        return t.user + t.system + t.children_user + t.children_system

    def close(self) -> None:
        if self.pool:
            self.pool.close()
            self.pool.join()


def train(args, runner: Runner, rng) -> tuple[np.ndarray, list[dict]]:
    stages = CURRICULUM if args.curriculum else [TASK]
    level = 0
    mean = np.zeros((4, len(FEATURES) + 1))
    std = np.full_like(mean, 0.5)
    n_elite = max(2, args.population // 5)
    curve = []
    for it in range(args.iterations):
        stage = stages[level]
        seeds = [1000 + it * args.seeds_per_candidate + j for j in range(args.seeds_per_candidate)]
        thetas = mean + std * rng.standard_normal((args.population, *mean.shape))
        scores = np.array([r for r, _ in runner.map([(t, seeds, stage) for t in thetas])])
        elite = thetas[np.argsort(scores, kind="stable")[-n_elite:]]
        mean, std = elite.mean(axis=0), elite.std(axis=0) + 0.02
        at_mean, goals = runner.map([(mean, seeds, stage)])[0]  # the new mean, on the same seeds
        curve.append(
            {
                "iteration": it + 1,
                "stage": stage,
                "episodes": (it + 1) * args.population * len(seeds),
                "population": float(scores.mean()),
                "elite": float(np.sort(scores)[-n_elite:].mean()),
                "best": float(scores.max()),
                "mean_policy": at_mean,
                "mean_policy_goals": goals,
            }
        )
        print(
            f"iteration {it + 1} ({stage}): return: population {scores.mean():.3f}, elite {curve[-1]['elite']:.3f},"
            f" new mean policy {at_mean:.3f} ({goals}/{len(seeds)} goals)",
            flush=True,
        )
        if level + 1 < len(stages) and goals * 2 >= len(seeds):
            level += 1
            std = np.maximum(std, args.restart_std)  # widen the search again for the harder start
            print(f"  next stage: {stages[level]}", flush=True)
    return mean, curve


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="runs/breakaway", help="output directory (runs/breakaway)")
    ap.add_argument("--iterations", type=int, default=50)
    ap.add_argument("--population", type=int, default=24)
    ap.add_argument("--seeds-per-candidate", type=int, default=6)
    ap.add_argument("--eval-seeds", type=int, default=50)
    ap.add_argument("--workers", type=int, default=2, help="processes that play candidates (2)")
    ap.add_argument("--restart-std", type=float, default=0.2, help="the search's least spread on a new stage")
    ap.add_argument("--no-curriculum", dest="curriculum", action="store_false", help="train on the task alone")
    ap.add_argument("--seed", type=int, default=0, help="the sampler's seed")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    runner = Runner(args.workers)
    t0, w0 = runner.cpu_seconds(), time.monotonic()
    mean, curve = train(args, runner, rng)
    runner.close()  # joins the workers, so their CPU time is counted
    runner = Runner(args.workers)
    result = {
        "training_cpu_seconds": round(runner.cpu_seconds() - t0, 1),
        "training_wall_seconds": round(time.monotonic() - w0, 1),
        "load_average": [round(x, 2) for x in __import__("os").getloadavg()],
        "eval_seeds": args.eval_seeds,
        "task": TASK,
    }
    cols, size = columns(), make_env().observation_space(AGENTS[0]).shape[0]
    thetas = {
        "trained": mean,
        "untrained": np.zeros_like(mean),  # where the search started: it stands still
        "random_initial": np.random.default_rng(args.seed).normal(0, 0.5, mean.shape),
    }
    eval_seeds = list(range(EVAL_SEED0, EVAL_SEED0 + args.eval_seeds))  # no training episode used these
    for name, theta in thetas.items():
        per_seed = runner.map([(theta, [s], TASK) for s in eval_seeds])
        goals = sum(g for _, g in per_seed)
        ret = float(np.mean([r for r, _ in per_seed]))
        result[name] = {"mean_return": round(ret, 4), "goals": goals}
        print(f"{name}: {goals} goals in {args.eval_seeds} held-out seeds, mean return {ret:.3f}", flush=True)
    runner.close()
    result["curve"] = curve
    trained = policy_of(mean, cols, size)
    save_policy(
        out / "policy.onnx", {1: trained, 2: trained}, base="basic-static", frame_skip=FRAME_SKIP, robots=ROBOTS
    )
    (out / "results.json").write_text(json.dumps(result, indent=2))
    write_scenario(out / "policy.onnx", out / "breakaway.scenario.toml")
    plot(curve, result, out / "learning-curve.png")
    print(f"wrote {out}/learning-curve.png, {out}/policy.onnx, {out}/results.json, {out}/breakaway.scenario.toml")


def write_scenario(policy: Path, path: Path) -> None:
    """The task's scenario with team a played by the policy file (its path as given: relative to the
    directory `arena scenario run` runs in), so `arena scenario run` judges the policy on any seeds. A
    scenario run plays on after a goal (the env's episode ends at the first): it passes when team a
    scores in the 8 s, even after conceding one."""
    blocks = SCENARIO.read_text().split("\n[[scenario]]\n")
    task = "[[scenario]]\n" + next(b for b in blocks[1:] if b.startswith(f'name = "{TASK}"')).rstrip() + "\n"
    path.write_text(task.replace('home = "basic-static"', f'home = "policy:{policy}"', 1))


def plot(curve, result, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = [c["episodes"] for c in curve]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(x, [c["population"] for c in curve], marker="o", label="population (sampled policies), mean")
    ax.plot(x, [c["elite"] for c in curve], marker="s", label="elite (best fifth), mean")
    ax.plot(x, [c["mean_policy"] for c in curve], marker="^", label="the refitted mean policy")
    for i in range(1, len(curve)):
        if curve[i]["stage"] != curve[i - 1]["stage"]:
            ax.axvline(x[i - 1], color="grey", lw=0.8, ls=":")
    n = result["eval_seeds"]
    ax.axhline(result["trained"]["mean_return"], color="green", ls="--", label=f"trained, {n} held-out seeds")
    ax.set_xlabel("training episodes (dotted: the next, harder start)")
    ax.set_ylabel("return (GoalReward(): +1 a goal)")
    ax.set_title("CEM, shared linear policy: a 2v2 breakaway against basic-static")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
