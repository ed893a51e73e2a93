"""ONNX policy files: exported with onnx's own helpers, played with onnxruntime.

Needs the `onnx` extra (pip install 'soccer-arena[onnx]'): onnx to write a file, onnxruntime to play
one. A file's graph has one input, `obs` (float32, `[1, D]`), and an output per robot it plays,
`action_<n>`, or one output `action` that every robot it plays shares; its metadata_props are
`policy_file.META`. schemas/README.md says how a robot's own computer runs it (C++, onnxruntime).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from arena.config import ConfigError
from arena.strategies.learned import DISCRETE, MLPPolicy, View

OPSET = 17
INSTALL = "pip install 'soccer-arena[onnx]'"


def obs_size_for(robots: int) -> int:
    """The flat observation's length for a team of `robots` (schemas/README.md)."""
    from arena.config import MatchConfig

    return View.of(MatchConfig(robots=robots), "a", robots).size


def team_of(size: int) -> int | None:
    """The team size whose observation has `size` numbers; None if none has."""
    for robots in range(1, 12):
        if obs_size_for(robots) == size:
            return robots
    return None


# ------------------------------------------------------------------- export
def _onnx():
    try:
        import onnx
    except ImportError:
        raise ImportError(f"writing an ONNX policy file needs onnx: {INSTALL}") from None
    return onnx


def mlp_model(policy: MLPPolicy) -> Any:
    """An `MLPPolicy` as an ONNX model: obs [1, D] -> Gemm, Tanh per layer -> action [1, out]."""
    onnx = _onnx()
    from onnx import TensorProto, helper, numpy_helper

    nodes, inits = [], []
    x = "obs"
    for i, (w, b) in enumerate(zip(policy.weights, policy.biases)):
        inits += [numpy_helper.from_array(w, f"W{i}"), numpy_helper.from_array(b, f"b{i}")]
        nodes += [
            helper.make_node("Gemm", [x, f"W{i}", f"b{i}"], [f"z{i}"], transB=1),
            helper.make_node("Tanh", [f"z{i}"], [f"h{i}"]),
        ]
        x = f"h{i}"
    nodes.append(helper.make_node("Identity", [x], ["action"]))
    out = policy.weights[-1].shape[0]
    graph = helper.make_graph(
        nodes,
        "mlp",
        [helper.make_tensor_value_info("obs", TensorProto.FLOAT, [1, policy.obs_size])],
        [helper.make_tensor_value_info("action", TensorProto.FLOAT, [1, out])],
        inits,
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name="soccer-arena")
    onnx.checker.check_model(model)
    return model


def _model_of(policy: Any) -> Any:
    onnx = _onnx()
    if isinstance(policy, MLPPolicy):
        return mlp_model(policy)
    if isinstance(policy, onnx.ModelProto):
        return policy
    if isinstance(policy, str | Path):
        return onnx.load(str(policy))
    raise TypeError(
        f"cannot export a {type(policy).__name__} to ONNX: give a LinearPolicy or MLPPolicy, an onnx.ModelProto "
        "(torch.onnx.export, docs/learning.md) or an .onnx file; or save a .pkl (which loads only with --allow-pickle)"
    )


def team_model(policies: dict[int, Any], meta: dict[str, str], obs_size: int | None) -> bytes:
    """One ONNX model for a team's policies (one shared graph, or one output per robot), with `meta`."""
    onnx = _onnx()
    from onnx import compose, helper

    distinct: list[Any] = []
    for p in policies.values():
        if not any(p is q for q in distinct):
            distinct.append(p)
    models = [_model_of(p) for p in distinct]
    for m in models:
        if len(m.graph.input) - len(m.graph.initializer) > 1 or len(m.graph.output) != 1:
            raise ValueError("a policy's ONNX graph takes one input (the observation) and gives one output")
    size = obs_size or _input_size(models[0])
    if len(models) == 1:
        model = models[0]
        model.graph.input[0].name, model.graph.output[0].name = _rename(model, "obs", "action")
    else:
        opset = max(o.version for m in models for o in m.opset_import if o.domain in ("", "ai.onnx"))
        nodes, inits, outputs = [], [], []
        for n, p in sorted(policies.items()):
            m = models[next(i for i, q in enumerate(distinct) if q is p)]
            m = compose.add_prefix(m, f"r{n}_")
            nodes.append(helper.make_node("Identity", ["obs"], [m.graph.input[0].name]))
            nodes.extend(m.graph.node)
            inits.extend(m.graph.initializer)
            nodes.append(helper.make_node("Identity", [m.graph.output[0].name], [f"action_{n}"]))
            out = onnx.ValueInfoProto()
            out.CopyFrom(m.graph.output[0])
            out.name = f"action_{n}"
            outputs.append(out)
        inp = onnx.ValueInfoProto()
        inp.CopyFrom(models[0].graph.input[0])
        inp.name = "obs"
        graph = helper.make_graph(nodes, "team", [inp], outputs, inits)
        model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", opset)], producer_name="soccer-arena")
    robots = int(meta["arena.team_size"])
    if size is not None and not robots:
        robots = team_of(size) or 0
    meta = meta | {"arena.team_size": str(robots), "arena.obs_size": str(size or "")}
    del model.metadata_props[:]
    for k, v in meta.items():
        model.metadata_props.add(key=k, value=v)
    onnx.checker.check_model(model)
    return model.SerializeToString()


def _input_size(model) -> int | None:
    dims = model.graph.input[0].type.tensor_type.shape.dim
    return dims[-1].dim_value if dims and dims[-1].HasField("dim_value") else None


def _rename(model, inp: str, out: str) -> tuple[str, str]:
    """Rename the graph's input and output, and every use of them."""
    old_in, old_out = model.graph.input[0].name, model.graph.output[0].name
    names = {old_in: inp, old_out: out}
    for node in model.graph.node:
        node.input[:] = [names.get(x, x) for x in node.input]
        node.output[:] = [names.get(x, x) for x in node.output]
    return inp, out


# --------------------------------------------------------------------- play
class OnnxPolicy:
    """Runs one output of an ONNX model on a flat observation: a Box action (4 floats) or a move index."""

    def __init__(self, session, output: str, shape: tuple[int, ...], discrete: bool):
        self.session = session
        self.output = output
        self.shape = shape
        self.discrete = discrete

    def __call__(self, obs: np.ndarray) -> Any:
        out = np.asarray(self.session.run([self.output], {"obs": obs.reshape(self.shape)})[0]).reshape(-1)
        if not self.discrete:
            return out
        if out.size == len(DISCRETE) and np.issubdtype(out.dtype, np.floating):
            return int(np.argmax(out))  # scores (logits) of the moves
        return out if out.size != 1 else out[0]


def load_onnx(path, data: bytes):
    """A policy file's ONNX model, checked: a valid graph, the input and outputs this file's
    metadata promises, frame_skip >= 1. ConfigError (one line) when any is not so."""
    from arena.strategies.policy_file import PolicyFile

    try:
        import onnxruntime as ort
    except ImportError:
        raise ConfigError(f"policy file {path}: reading an ONNX policy needs onnxruntime: {INSTALL}") from None

    def bad(why: str) -> ConfigError:
        return ConfigError(f"policy file {path}: {why}")

    ort.set_default_logger_severity(4)  # a model's failure is our one line, not onnxruntime's log on stderr
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = opts.inter_op_num_threads = 1  # ten processes share the cores; one decision is small
    opts.log_severity_level = 4
    try:
        session = ort.InferenceSession(data, opts, providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime's own errors: not a model, an invalid graph, an unknown op
        first = (str(exc).strip().splitlines() or [""])[0][:160]
        raise ConfigError(
            f"policy file {path} is not a valid ONNX model ({first}); a policy file is ONNX "
            "(arena.learn.save_policy), recorded actions, or with --allow-pickle a pickle"
        ) from None
    meta = session.get_modelmeta().custom_metadata_map
    missing = [k for k in ("arena.base", "arena.robots", "arena.frame_skip", "arena.actions") if k not in meta]
    if missing:
        raise bad(f"its metadata_props lack {', '.join(missing)} (arena.learn.save_policy writes them)")
    try:
        frame_skip = int(meta["arena.frame_skip"])
        team_size = int(meta.get("arena.team_size") or 0)
        numbers = [int(x) for x in meta["arena.robots"].split(",")]
    except ValueError:
        raise bad("arena.frame_skip, arena.team_size and arena.robots must be integers") from None
    if frame_skip < 1:
        raise bad(f"arena.frame_skip must be at least 1, got {frame_skip}")
    if meta["arena.actions"] not in ("box", "discrete"):
        raise bad(f"arena.actions must be box or discrete, got {meta['arena.actions']!r}")
    discrete = meta["arena.actions"] == "discrete"
    if not numbers or any(not 0 <= n <= 10 for n in numbers) or not 0 <= team_size <= 11:
        raise bad("arena.robots must name robot numbers 0..10, arena.team_size be 0..11")
    inputs = session.get_inputs()
    if len(inputs) != 1 or inputs[0].name != "obs" or inputs[0].type != "tensor(float)":
        got = ", ".join(f"{i.name} {i.type}" for i in inputs)
        raise bad(f"the model takes {got}; a policy takes one input, obs, a float tensor")
    dims = inputs[0].shape
    if len(dims) not in (1, 2) or not isinstance(dims[-1], int):
        raise bad(f"its input obs has shape {dims}; a policy's is [1, D] or [D]")
    size = dims[-1]
    expect = obs_size_for(team_size) if team_size else None
    if expect is None and team_of(size) is None:
        raise bad(f"its input obs has {size} numbers, the observation of no team size")
    if expect is not None and size != expect:
        raise bad(f"its input obs has {size} numbers; the observation of a team of {team_size} has {expect}")
    shape = (1, size) if len(dims) == 2 else (size,)
    outputs = {o.name for o in session.get_outputs()}
    policies = {}
    for n in numbers:
        name = f"action_{n}" if f"action_{n}" in outputs else "action"
        if name not in outputs:
            raise bad(f"no output action_{n} or action for robot {n} (outputs: {', '.join(sorted(outputs))})")
        policies[n] = OnnxPolicy(session, name, shape, discrete)
    return PolicyFile(meta["arena.base"], policies, frame_skip, discrete, team_size or team_of(size) or 0)
