"""schemas/README.md's section on playing a learned policy (an ONNX file) in a robot of another language.

The observation it specifies is `arena.strategies.learned.observe`; tests/unit/test_policy_contract.py
holds this text to that function's parts, sizes and bounds and to the discrete moves.
"""

from __future__ import annotations

from typing import get_args

from arena.schemas.vocabulary import RefCommandName

COMMANDS = get_args(RefCommandName)
_ONE_HOT = ", ".join(f"{i} {c}" for i, c in enumerate(COMMANDS))
N = len(COMMANDS)

POLICY = f"""
## Playing a learned policy (ONNX)

A policy file written by `arena.learn.save_policy` (docs/learning.md) is an ONNX model; the strategy
`policy:FILE.onnx` plays it in a match, and a robot of its own runs it with onnxruntime on its own
computer. What the file holds:

* one input, `obs`: float32, shape `[1, D]` (or `[D]`), the observation below;
* per robot it plays, an output `action_<n>` (robot number n), or one output `action` that every robot
  it plays shares: float32 `[1, 4]` (a box action: vx, vy, omega, kick, each in [-1, 1]), or for
  `arena.actions = discrete` an int64 index 0..9 or float scores `[1, 10]` (the largest wins);
* `metadata_props`: `arena.base` (the strategy of the base station and of the robots it does not play),
  `arena.robots` (the robot numbers it plays, e.g. `1,2`), `arena.frame_skip` (ticks per decision, >= 1),
  `arena.actions` (`box` or `discrete`), `arena.team_size` (r below: the team size its observation is
  shaped for), `arena.obs_size` (D).

**When it decides.** At every tick k with k mod `frame_skip` = 0, from the same two messages a robot
acts on (its `sense` of tick k - L and the latest `order`, "A robot's schedule" above); its action is
held for the ticks in between. The `cmd` of every tick k is: `vx` = clip(a0) x max_speed, `vy` =
clip(a1) x max_speed (body frame), `omega` = clip(a2) x max_omega, `dribbler` = true, `kick_speed` =
max(0, clip(a3)) x kick_max_speed, clip meaning clamp to [-1, 1]; `max_speed`, `max_omega`,
`kick_max_speed` are the configuration's `robot` fields. A discrete index i plays the box action of
row i: 0 stop (0, 0, 0, 0), 1 forward (0.4, 0, 0, 0), 2 backward (-0.4, 0, 0, 0), 3 left (0, 0.4, 0, 0),
4 right (0, -0.4, 0, 0), 5 forward-left (0.3, 0.3, 0, 0), 6 forward-right (0.3, -0.3, 0, 0),
7 turn-left (0, 0, 0.5, 0), 8 turn-right (0, 0, -0.5, 0), 9 kick (0.2, 0, 0, 1). An action that is not
finite, or an index outside 0..9, is an error (stop the robot), never a move.

**The observation**, D = 45 + 8r numbers (69 for r = 3), computed in double precision, then rounded to
float32 and each clamped to its part's bounds. Notation: `hl`, `hw` half the field's length and width
(`field`); `s` the attack direction, `order.attack_dir` once an order has arrived, before that +1 for
team a and -1 for team b (so +x always points at the opponent goal); `(px, py, th)` = `sense.pose`
(world frame), or (0, 0, 0) before the first `sense`; `c` = cos th, `sn` = sin th; for a point (x, y),
its body-frame offset is `fwd` = c dx + sn dy, `left` = -sn dx + c dy with dx = x - px, dy = y - py.

| part | numbers | bounds | content, in order |
|---|---|---|---|
| self | 7 | [-2, 2] | s px / hl, s py / hw, s c, s sn, `sense.vx` / max_speed, `sense.vy` / max_speed, `sense.omega` / max_omega; before the first `sense`: 0, 0, 1, 0, 0, 0, 0 |
| ball | 7 | [-30, 30] | if `sense.ball.visible`: 1, s x / hl, s y / hw, fwd, left, hypot(dx, dy) of the ball's (x, y); else six zeros; then 1 if `sense.has_ball` else 0 |
| goal | 2 | [-30, 30] | fwd, left of the point (s hl, 0), the opponent goal's centre |
| team_ball | 4 | [-2, 60] | if `order.ball_valid`: 1, s `ball_x` / hl, s `ball_y` / hw, min(`ball_age` x dt, 60) with dt = `timing.dt`; else four zeros |
| robots | 4 * (2 * r - 1) | [-30, 30] | every robot of `sense.robots` as (d2, side, fwd, left), d2 = dx^2 + dy^2, side +1 for its own team and -1 for the other; sorted ascending (by d2, then side, fwd, left); the first 2r - 1 as 1, side, fwd, left; then zeros for the slots left |
| referee | {N + 5} | [-2, 2] | {N} numbers, 1 at the index of `order.command` ({_ONE_HOT}), else 0; 3 numbers, 1 at the first if `order.command_team` is the robot's own team, the third if it is "", else the second; then s `spot_x` / hl, s `spot_y` / hw. Before the first order: STOP, the third, 0, 0 |
| role | 4 | [0, 1] | 1 at `order.role`'s index among goalkeeper, defender, attacker, and at the fourth for any other role or before the first order |

**In C++** (onnxruntime's C++ API; link `onnxruntime`):

```cpp
#include <onnxruntime_cxx_api.h>
Ort::Env env(ORT_LOGGING_LEVEL_WARNING, "robot");
Ort::SessionOptions opts;
opts.SetIntraOpNumThreads(1);
Ort::Session session(env, "policy.onnx", opts);
Ort::AllocatorWithDefaultOptions alloc;
Ort::ModelMetadata meta = session.GetModelMetadata();
int frame_skip = std::stoi(meta.LookupCustomMetadataMapAllocated("arena.frame_skip", alloc).get());
int D = std::stoi(meta.LookupCustomMetadataMapAllocated("arena.obs_size", alloc).get());
std::vector<float> obs = observe(sense, order);   // the D numbers above
std::array<int64_t, 2> shape{{1, D}};
Ort::MemoryInfo mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
Ort::Value in = Ort::Value::CreateTensor<float>(mem, obs.data(), obs.size(), shape.data(), shape.size());
const char* inputs[] = {{"obs"}};
const char* outputs[] = {{"action_1"}};   // robot 1; "action" if the file has that output instead
std::vector<Ort::Value> out = session.Run(Ort::RunOptions{{nullptr}}, inputs, &in, 1, outputs, 1);
const float* a = out[0].GetTensorData<float>();   // vx, vy, omega, kick in [-1, 1]: the cmd above
```

`arena match --home policy:FILE.onnx --external a/1` then plays the rest of the match while your robot
plays a/1 from the same file; its digest is the one the env gives for the same seed
(tests/integration/test_learn_deploy.py plays the file through `arena match` on both engines).
"""
