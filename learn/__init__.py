"""Learning environments over the in-process engine: PettingZoo and Gymnasium (docs/learning.md).

`SoccerParallelEnv` (PettingZoo `ParallelEnv`, any subset of either team's
robots), `SoccerEnv` (Gymnasium, one robot), `make_vector_env` (N worker
processes), and the policy files a match plays as the strategy `policy:PATH`.
Needs the `learn` extra: pip install 'soccer-arena[learn]'.
May import arena.scenarios, arena.match and every package below them; only the CLI imports it.
"""

try:
    import gymnasium
    import pettingzoo  # noqa: F401
except ImportError:
    raise ImportError("arena.learn needs the learn extra: pip install 'soccer-arena[learn]'") from None

from arena.learn.parallel import SoccerParallelEnv
from arena.learn.rewards import GoalReward, Outcome
from arena.learn.single import SoccerEnv, make_vector_env
from arena.learn.vector import SoccerVectorEnv
from arena.strategies.learned import (
    DISCRETE,
    LinearPolicy,
    RecordedActions,
    load_policy,
    obs_fields,
    save_policy,
)

__all__ = [
    "DISCRETE",
    "GoalReward",
    "LinearPolicy",
    "Outcome",
    "RecordedActions",
    "SoccerEnv",
    "SoccerParallelEnv",
    "SoccerVectorEnv",
    "load_policy",
    "make_vector_env",
    "obs_fields",
    "save_policy",
]

if "arena/Soccer-v0" not in gymnasium.registry:
    gymnasium.register("arena/Soccer-v0", entry_point="arena.learn.single:SoccerEnv")
