"""Train SoccerParallelEnv's agents with RLlib's PPO on a Ray instance: one shared policy for a/1 and a/2.

    python examples/learn_rllib/ppo.py --iterations 5                  # a local Ray instance
    python examples/learn_rllib/ppo.py --address auto --runners 4      # a running Ray cluster (docs/cluster.md)

Needs the `learn` and `rllib` extras and torch: pip install 'soccer-arena[learn,rllib,sb3]'.
The env is the PettingZoo ParallelEnv, wrapped by RLlib's own ParallelPettingZooEnv; every env runner
plays its own matches (the in-process engine), seeded by RLlib.
"""

from __future__ import annotations

import argparse
import json


def config(runners: int, half_time: float):
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv
    from ray.tune.registry import register_env

    from arena.learn import GoalReward, SoccerParallelEnv

    def make(env_config):
        return ParallelPettingZooEnv(
            SoccerParallelEnv(
                agents=["a/1", "a/2"],
                home="AD",
                away="BS",
                half_time=env_config.get("half_time", 10.0),
                frame_skip=5,
                reward=GoalReward(progress=0.2),
            )
        )

    register_env("arena-soccer", make)
    return (
        PPOConfig()
        .environment("arena-soccer", env_config={"half_time": half_time})
        .multi_agent(policies={"shared"}, policy_mapping_fn=lambda agent_id, *args, **kwargs: "shared")
        .env_runners(num_env_runners=runners, rollout_fragment_length=100)
        .training(train_batch_size=400, minibatch_size=100, num_epochs=2)
    )


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--iterations", type=int, default=5)
    p.add_argument("--runners", type=int, default=0, help="env runner actors (0: in the driver)")
    p.add_argument("--half-time", type=float, default=10.0)
    p.add_argument("--address", default=None, help="a Ray cluster's address (default: a local instance)")
    args = p.parse_args(argv)
    import ray

    ray.init(address=args.address, include_dashboard=False, num_cpus=None if args.address else 2)
    try:
        algo = config(args.runners, args.half_time).build_algo()
        results = []
        for i in range(args.iterations):
            r = algo.train()
            steps = r["env_runners"]["num_env_steps_sampled_lifetime"]
            ret = r["env_runners"].get("episode_return_mean")
            results.append({"iteration": i + 1, "env_steps": steps, "episode_return_mean": ret})
            print(json.dumps(results[-1]), flush=True)
        algo.stop()
        return {"iterations": results}
    finally:
        ray.shutdown()


if __name__ == "__main__":
    main()
