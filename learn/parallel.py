"""`SoccerParallelEnv`: a PettingZoo `ParallelEnv` whose episodes are real matches.

Agents are the robots a learner controls, any subset of either team ("a/1",
"b/0", ...); every other robot, and both base stations, are played by the
team's named strategy (a built-in or a plugin), and the referee plays too: set
pieces happen, and a learner that breaks a rule gets the foul. Learn a/1 and
a/2 with AD's keeper against BS::

    env = SoccerParallelEnv(agents=["a/1", "a/2"], home="AD", away="BS")

Observation: what that robot receives at the tick it acts, its `sense` of
tick k - L (the perception latency) and its base station's latest `order`
(which carries the referee's command), in the robot's attack frame
(`arena.strategies.learned.obs_fields`, docs/learning.md): a `Box`
(`obs="flat"`) or a `Dict` of named `Box`es (`obs="dict"`).

Action: `Box(-1, 1, (4,))`, (vx, vy, omega, kick) scaled by the robot's
limits, or `Discrete(10)` (`actions="discrete"`, `DISCRETE`).

A step is one control tick (20 ms) or `frame_skip` ticks with the action held.
An episode is one match (`half_time` seconds a half, both halves; `until="half"`
stops at half time); it is truncated when that ends, and terminated at a goal
(`end_on_goal`). The reward is `reward(agent, Outcome)` (`arena.learn.rewards`),
by default +1 a goal scored, -1 a goal conceded.

`reset(seed=s)` plays the match of seed s, and `reset(seed=s, options={"scenario":
PATH})` that scenario's run, judged after every step and terminated once its verdict
is decided (`end_on_verdict`). The same seed and actions give the
same match, digest for digest (`digests()`), as `arena match` gives when the robots
play those actions from the file `save_actions` writes (`policy:PATH`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from arena.config import MAX_HALF_TIME, MatchConfig, ProcessId
from arena.learn.match import SteppedMatch
from arena.learn.rewards import GoalReward, Outcome
from arena.learn.views import Renderer, action_mask, state, state_space
from arena.strategies import registry
from arena.strategies.learned import DISCRETE, View, discrete_index, obs_fields, observe
from arena.strategies.policy_file import save_recorded


def episode_seed(stream: np.random.SeedSequence) -> int:
    """The next match seed (0 .. 2**63 - 1) of a stream: a fresh child's first 63 bits."""
    return int(stream.spawn(1)[0].generate_state(1, np.uint64)[0] >> np.uint64(1))


def agent_name(text: str) -> str:
    """ "a/1", "robot/a/1" -> "a/1"; ValueError for anything else."""
    pid = ProcessId.parse(text)
    if pid.kind != "robot":
        raise ValueError(f"{text!r} is not a robot (agents are robots such as a/1)")
    return pid.short


# A box action may stand a float32 rounding beyond +-1 (an exported tanh gives -1.0000001); it is clipped.
BOX_SLACK = 1.0 + 1e-6


class SoccerParallelEnv(ParallelEnv):
    metadata = {"name": "soccer_arena_v0", "render_modes": ["rgb_array"], "is_parallelizable": True}

    def __init__(
        self,
        agents: list[str] | tuple[str, ...] = ("a/1",),
        home: str = "advance-dynamic",
        away: str = "basic-static",
        *,
        robots: int = 3,
        half_time: float = 30.0,
        frame_skip: int = 1,
        obs: str = "flat",
        actions: str = "box",
        reward=None,
        end_on_goal: bool = True,
        end_on_verdict: bool = True,
        until: str = "match",
        config: MatchConfig | None = None,
        render_mode: str | None = None,
    ):
        base = config or MatchConfig()
        if isinstance(robots, bool) or not isinstance(robots, int) or not 1 <= robots <= 6:
            raise ValueError(f"robots must be 1..6 a team, goalkeeper included, got {robots!r}")
        if isinstance(half_time, bool) or not isinstance(half_time, int | float) or not 0 < half_time <= MAX_HALF_TIME:
            raise ValueError(f"half_time must be in (0, {MAX_HALF_TIME:g}] seconds a half, got {half_time!r}")
        self.cfg = base.replace(
            home=registry.resolve_name(home), away=registry.resolve_name(away), robots=robots, half_time=half_time
        )
        if isinstance(agents, str):  # "a/1": one agent, not the characters of its name
            agents = [agents]
        names = [agent_name(a) for a in agents]
        if not names or len(set(names)) != len(names):
            raise ValueError(f"agents must be distinct robots, got {list(agents)}")
        for a in names:
            if int(a.split("/")[1]) >= robots:
                raise ValueError(f"no robot {a} in a match of {robots} robots a team")
        choices = {"obs": (obs, ("flat", "dict")), "actions": (actions, ("box", "discrete"))}
        for option, (value, allowed) in (choices | {"until": (until, ("match", "half"))}).items():
            if value not in allowed:
                raise ValueError(f"{option} must be {' or '.join(allowed)}, got {value!r}")
        if isinstance(frame_skip, bool) or not isinstance(frame_skip, int) or frame_skip < 1:
            raise ValueError(f"frame_skip must be an integer of at least 1, got {frame_skip!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.render_mode = render_mode
        self._renderer = Renderer()
        self.possible_agents = names
        self.agents: list[str] = []
        self.frame_skip = frame_skip
        self.obs_form = obs
        self.discrete = actions == "discrete"
        self.reward_fn = reward or GoalReward()
        self.end_on_goal = end_on_goal
        self.end_on_verdict = end_on_verdict
        self.until = until
        self._views = {a: View.of(self.cfg, a[0]) for a in names}
        flat = spaces.Box(self._views[names[0]].low, self._views[names[0]].high, dtype=np.float32)
        self._flat_space = flat
        self._parts = []
        i = 0
        for name, n, _, _, _ in obs_fields(robots):
            self._parts.append((name, i, i + n))
            i += n
        dict_space = spaces.Dict(
            {name: spaces.Box(flat.low[a:b], flat.high[a:b], dtype=np.float32) for name, a, b in self._parts}
        )
        self._obs_space = flat if obs == "flat" else dict_space
        self._act_space = spaces.Discrete(len(DISCRETE)) if self.discrete else spaces.Box(-1.0, 1.0, (4,), np.float32)
        self.state_space = state_space(robots)
        self._state_team = names[0][0]
        self.match: SteppedMatch | None = None
        self._seed = self.cfg.seed
        self._stream: np.random.SeedSequence | None = None
        self.recorded: dict[str, list[Any]] = {}
        self.scenario = None
        self.verdict: dict[str, Any] | None = None

    # ------------------------------------------------------------- spaces
    def observation_space(self, agent: str) -> spaces.Space:
        return self._obs_space

    def action_space(self, agent: str) -> spaces.Space:
        return self._act_space

    # ---------------------------------------------------------------- API
    def reset(self, seed: int | None = None, options: dict | None = None):
        """Start the match of `seed` (when None: the next of a stream of seeds that the last given seed, or
        fresh entropy, began; the seed played is in the infos), or with `options={"scenario": S}`
        the run of scenario S (a file with one scenario, a (path, name) pair, or an `arena.scenarios.Scenario`)."""
        if seed is not None:
            self._seed = int(seed) % 2**63
            self._stream = np.random.SeedSequence(self._seed)
        else:  # the next seed of the stream the last seed began, or of fresh entropy
            if self._stream is None:
                self._stream = np.random.SeedSequence()
            self._seed = episode_seed(self._stream)
        cfg = self.cfg.replace(seed=self._seed)
        scenario = (options or {}).get("scenario")
        self.scenario = None if scenario is None else self._scenario(scenario)
        if self.scenario is not None:
            cfg = self.scenario.config(self._seed, base=cfg)
            if cfg.robots != self.cfg.robots:
                raise ValueError(
                    f"scenario {self.scenario.name!r} plays {cfg.robots} robots a team, this env {self.cfg.robots}"
                )
        self.verdict: dict[str, Any] | None = None
        self.last_outcomes: dict[str, Outcome] = {}  # the last step's, by team
        self.match = SteppedMatch(cfg, self.possible_agents, self.frame_skip, self.discrete, keep=bool(scenario))
        self.agents = list(self.possible_agents)
        self.recorded = {a: [] for a in self.agents}
        self.match.advance()
        self._last_score = self.match.score
        self._last_ball = self.match.ball
        flat = self._flat()
        return {a: self._shape(f) for a, f in flat.items()}, {a: self._info(flat[a]) for a in self.agents}

    def step(self, actions: dict[str, Any]):
        m = self.match
        if m is None or not self.agents:
            raise RuntimeError("step() before reset(), or after the episode ended")
        self._check(actions)
        for a in self.agents:
            self.recorded[a].append(np.array(actions[a]))  # a copy: callers may reuse one array
        m.act(actions)
        m.advance()
        ga = m.score[0] - self._last_score[0]
        gb = m.score[1] - self._last_score[1]
        progress, closing = m.progress_a, {"a": 0.0, "b": 0.0}
        if m.ball is not None and self._last_ball is not None:
            hl = m.cfg.field.length / 2
            for team, gx in (("a", hl * m.attack_dir_a), ("b", -hl * m.attack_dir_a)):
                before = math.hypot(self._last_ball[0] - gx, self._last_ball[1])
                closing[team] = before - math.hypot(m.ball[0] - gx, m.ball[1])
        self._last_score, self._last_ball = m.score, m.ball
        goal = (ga or gb) and self.end_on_goal
        over = m.over or (self.until == "half" and m.tick >= m.cfg.half_ticks)
        passed, decided = None, False
        if self.scenario is not None:
            verdict = self._judge(None if goal or over else m.tick)
            decided = self.end_on_verdict and verdict["decided"]
            if goal or over or decided:
                self.verdict = verdict
                passed = verdict["passed"]
        restarts = m.restarts
        out = {
            team: Outcome(
                m.tick,
                team,
                ga if team == "a" else gb,
                gb if team == "a" else ga,
                progress if team == "a" else -progress,
                m.new_commands,
                closing[team],
                passed,
                *(_restarts_of(restarts, team) if restarts else ((), (), 0)),  # most steps: none (no generators)
            )
            for team in ("a", "b")
        }
        self.last_outcomes = out
        rewards = {a: float(self.reward_fn(a, out[a[0]])) for a in self.agents}
        ended = bool(goal) or (decided and not over)  # a terminal state: a goal, or the scenario's verdict
        terms = {a: ended for a in self.agents}
        truncs = {a: bool(over and not ended) for a in self.agents}
        flat = self._flat()
        obs = {a: self._shape(f) for a, f in flat.items()}
        infos = {a: self._info(flat[a]) for a in self.agents}
        if ended or over:
            self.agents = []
        return obs, rewards, terms, truncs, infos

    def close(self) -> None:
        self.match = None

    @staticmethod
    def _refuse_box(a: str, act: Any) -> None:
        try:
            v = np.asarray(act, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{a}: a box action is 4 numbers in [-1, 1], got {act!r:.80}") from None
        if v.shape != (4,):
            raise ValueError(f"{a}: a box action has shape (4,) (vx, vy, omega, kick), got {v.shape}")
        if not np.isfinite(v).all():
            raise ValueError(f"{a}: a box action's numbers must be finite, got {v.tolist()}")
        raise ValueError(f"{a}: a box action's numbers are in [-1, 1], got {v.tolist()}")  # beyond BOX_SLACK

    def _check(self, actions: dict[str, Any]) -> None:
        """ValueError, naming the agent, for an action that is missing, of the wrong shape, not finite or
        out of range (a NaN would play as full reverse, a discrete -1 as the last move)."""
        if not isinstance(actions, dict):
            raise ValueError(f"step() takes a dict of actions by agent, got {type(actions).__name__}")
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise ValueError(f"no action for {', '.join(missing)} (step() needs one for every agent: {self.agents})")
        for a in self.agents:
            act = actions[a]
            if self.discrete:
                try:
                    discrete_index(act)
                except ValueError as exc:
                    raise ValueError(f"{a}: {exc}") from None
                continue
            v = act.tolist() if isinstance(act, np.ndarray) else act
            try:
                if len(v) == 4 and all(-BOX_SLACK <= x <= BOX_SLACK for x in v):  # False for NaN: one test a step
                    continue
            except TypeError:
                pass
            self._refuse_box(a, act)

    # -------------------------------------------------------------- extras
    def digests(self) -> dict[str, str]:
        """Every process's digest so far: after a whole episode, those of `arena match` (docs/learning.md)."""
        return self.match.digests() if self.match is not None else {}

    def save_actions(self, team: str, path) -> str:
        """A policy file that replays this episode's actions of `team`'s learners, the rest of the team
        by its strategy: `arena match --home policy:PATH` (team a) plays this episode again."""
        mine = {int(a.split("/")[1]): self.recorded[a] for a in self.recorded if a[0] == team}
        cfg = self.match.cfg if self.match is not None else self.cfg  # a scenario names its own strategies
        return str(save_recorded(path, mine, cfg.strategy_of(team), self.frame_skip, self.discrete, cfg.robots))

    def observe(self, agent: str) -> Any:
        return self._shape(observe(*self.match.seen(agent), self._views[agent]))

    def _flat(self) -> dict[str, np.ndarray]:
        return {a: observe(*self.match.seen(a), self._views[a]) for a in self.agents}

    def state(self) -> np.ndarray:
        """Ground truth for a centralised critic, in the attack frame of the first agent's team (views.state)."""
        return state(self.match, self._state_team)

    def render(self) -> np.ndarray | None:
        """render_mode "rgb_array": the field now, as match.gif draws it (HEIGHT x WIDTH x 3, uint8)."""
        if self.render_mode != "rgb_array":
            return None
        return self._renderer(self.match)

    def _shape(self, flat: np.ndarray) -> Any:
        if self.obs_form == "flat":
            return flat
        return {name: flat[a:b] for name, a, b in self._parts}

    def _info(self, flat: np.ndarray) -> dict[str, Any]:
        m = self.match
        info: dict[str, Any] = {"tick": m.tick, "score": m.score, "seed": self._seed}
        if self.discrete:
            info["action_mask"] = action_mask(flat)
        if self.verdict is not None:
            info["scenario"] = self.verdict
        return info

    # ----------------------------------------------------------- scenarios
    @staticmethod
    def _scenario(scenario: Any):
        """A scenario (arena.scenarios), or the path of a file holding exactly one, or (path, name)."""
        from arena.scenarios import Scenario, load

        if isinstance(scenario, Scenario):
            return scenario
        if isinstance(scenario, tuple):
            return load(*scenario)
        return load(scenario)

    def _judge(self, now: int | None) -> dict[str, Any]:
        """Every expectation of the scenario, judged on the episode so far (arena.scenarios.expect).

        `now`: the tick played to, mid-episode (None at its end). A judgement is final once the tick it
        names is past: a "happens" kind that happened, a "never" kind that was broken, or any kind whose
        window is over. `decided`: a final failure, or every judgement final."""
        from arena.scenarios.expect import Trace, judge

        m, sc = self.match, self.scenario
        f = m.cfg.field
        trace = Trace(
            dt=m.cfg.timing.dt,
            worlds=m.worlds,
            commands=[c for r in m.referees for c in r.commands],
            digests=m.digests(),
            fence=(f.length / 2 + f.runoff, f.width / 2 + f.runoff),
        )
        failures, final = [], []
        for e in sc.spec.expect:
            ok, tick, detail = judge(e, trace, sc.spec.time_limit)
            final.append(now is None or tick < now)  # frames of tick `now` may still come
            if not ok:
                failures.append({"expectation": e.name, "tick": tick, "detail": detail, "final": final[-1]})
        decided = bool(final) and (all(final) or any(x["final"] for x in failures))  # none: only the time limit
        return {"name": sc.name, "passed": not failures, "failures": failures, "decided": decided}


def _restarts_of(restarts: list, team: str) -> tuple[tuple[str, ...], tuple[str, ...], float]:
    """`Outcome`'s restarts for `team`: its own, the opponents', and what the opponents' charged back."""
    return (
        tuple(r.name for r in restarts if r.team == team),
        tuple(r.name for r in restarts if r.team not in ("", team)),
        sum(max(0.0, r.banked if team == "a" else -r.banked) for r in restarts if r.team not in ("", team)),
    )
