"""A policy file a user or a peer hands over never runs code when loaded: a pickle that would write a
marker file is handed to every path that loads a policy, and the marker never appears. A bad ONNX file
is one line and exit 2 before any process starts."""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.integration.helpers import ARENA, arena_json

pytest.importorskip("onnxruntime")

from arena.learn import LinearPolicy, save_policy
from arena.strategies.learned import obs_fields

REFUSED = "is a pickle, and loading a pickle runs any code it holds: refused"


class _Plant:
    """Unpickled, it calls open(marker, "w"): the file appears."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (open, (str(self.marker), "w"))


def _plant(tmp_path: Path) -> tuple[Path, Path]:
    marker = tmp_path / "MARKER"
    path = tmp_path / "evil.pkl"
    path.write_bytes(pickle.dumps(_Plant(marker)))
    return path, marker


def _arena(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([*ARENA, *args], capture_output=True, text=True, timeout=240, cwd=cwd)


def _scenario(folder: Path, policy: Path) -> Path:
    folder.mkdir()
    path = folder / "evil.scenario.toml"
    path.write_text(
        f'[[scenario]]\nname = "evil"\ntime_limit = 1.0\n\n[scenario.play]\nhome = "policy:{policy}"\n'
        'away = "BS"\nrobots = 2\n'
    )
    return path


def test_a_pickle_never_runs_on_any_path_that_loads_a_policy(tmp_path):
    evil, marker = _plant(tmp_path)
    size = sum(n for _, n, *_ in obs_fields(2))
    good = save_policy(tmp_path / "good.onnx", {1: LinearPolicy(np.zeros((4, size)), np.zeros(4))}, "BS", robots=2)
    # a recording whose configuration names a policy file; then the file is swapped for the pickle
    record = tmp_path / "rec.mcap"
    named = tmp_path / "named.pkl"
    named.write_bytes(good.read_bytes())
    arena_json(
        "match",
        "--home",
        f"policy:{named}",
        "--away",
        "BS",
        "--robots",
        "2",
        "--half-time",
        "1",
        "--record",
        str(record),
    )
    named.write_bytes(evil.read_bytes())
    scenario = _scenario(tmp_path / "scenarios", evil)
    robot = ("run", "robot", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--team", "a", "--robot", "1")
    paths = {
        "arena match": ("match", "--home", f"policy:{evil}", "--away", "BS"),
        "arena run robot --policy": (*robot, "--policy", str(evil)),
        "arena scenario run": ("scenario", "run", str(scenario)),
        "arena replay": ("replay", str(record), "--process", "robot/a/1"),
        "arena tournament": ("tournament", "--strategies", f"policy:{evil},BS", "--out", str(tmp_path / "t")),
    }
    for what, args in paths.items():
        r = _arena(*args)
        assert not marker.exists(), f"{what} ran the pickle's code"
        assert r.returncode == 2 and REFUSED in r.stderr, (what, r.returncode, r.stderr[-2000:])
        assert len(r.stderr.strip().splitlines()) == 1, (what, r.stderr)
    collect = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", str(scenario.parent)],
        capture_output=True,
        text=True,
        timeout=240,
        cwd=tmp_path,
    )
    assert not marker.exists(), "pytest --collect-only ran the pickle's code"
    assert REFUSED in collect.stdout + collect.stderr, collect.stdout[-2000:]


def test_a_pickle_plays_with_the_opt_in_that_says_it_runs_code(tmp_path):
    size = sum(n for _, n, *_ in obs_fields(2))
    path = save_policy(tmp_path / "p.pkl", {1: LinearPolicy(np.zeros((4, size)), np.zeros(4))}, "BS", robots=2)
    assert path.read_bytes()[:1] == b"\x80"
    r = _arena("match", "--home", f"policy:{path}", "--away", "BS", "--robots", "2", "--half-time", "1")
    assert r.returncode == 2 and REFUSED in r.stderr and "--allow-pickle" in r.stderr
    got = arena_json(
        *("match", "--home", f"policy:{path}", "--away", "BS", "--robots", "2", "--half-time", "1", "--allow-pickle")
    )
    assert got["ticks"] == 100
    assert "RUNS ANY CODE" in _arena("match", "--help").stdout.replace("\n", " ")


def _onnx(tmp_path: Path, name: str, **changes) -> Path:
    """An ONNX policy file with one thing wrong."""
    import onnx

    size = sum(n for _, n, *_ in obs_fields(3))
    path = save_policy(tmp_path / f"{name}.onnx", {1: LinearPolicy(np.zeros((4, size)), np.zeros(4))}, "BS")
    model = onnx.load(str(path))
    meta = {p.key: p.value for p in model.metadata_props} | changes.pop("meta", {})
    del model.metadata_props[:]
    for k, v in meta.items():
        if v is not None:
            model.metadata_props.add(key=k, value=v)
    if "weights" in changes:
        from onnx import numpy_helper

        w = changes["weights"]
        model.graph.initializer[0].CopyFrom(numpy_helper.from_array(w, "W0"))
        model.graph.initializer[1].CopyFrom(numpy_helper.from_array(np.zeros(w.shape[0], np.float32), "b0"))
    path.write_bytes(model.SerializeToString())
    return path


@pytest.mark.parametrize(
    ("name", "changes", "said"),
    [
        ("skip0", {"meta": {"arena.frame_skip": "0"}}, "arena.frame_skip must be at least 1, got 0"),
        ("nometa", {"meta": {"arena.base": None}}, "its metadata_props lack arena.base"),
        ("size", {"meta": {"arena.team_size": "2"}}, "the observation of a team of 2 has"),
        ("wide", {"weights": np.zeros((5, 69), np.float32)}, "not 4 numbers"),
        ("garbage", {}, "is not a valid ONNX model"),
    ],
)
def test_a_bad_onnx_file_is_one_line_before_any_process_starts(tmp_path, name, changes, said):
    path = _onnx(tmp_path, name, **changes)
    if name == "garbage":
        path.write_bytes(b"\x08\x07 not a model at all")
    r = _arena("match", "--home", f"policy:{path}", "--away", "BS", "--half-time", "1")
    assert r.returncode == 2, r.stderr
    assert said in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "gave up" not in r.stderr and "Traceback" not in r.stderr


def _fails_once_the_first_order_arrives(path: Path) -> Path:
    """A model that passes the load check (its trial observation reads STOP) and gives -inf once a robot's
    first order (KICKOFF) arrives, at tick 2 or 3: log of the STOP one-hot."""
    from onnx import TensorProto, helper, numpy_helper

    stop = 7 + 7 + 2 + 4 + 4 * 5 + 1  # the referee part's STOP, 3 robots a team
    consts = {"s": [stop], "e": [stop + 1], "ax": [1]}
    graph = helper.make_graph(
        [
            helper.make_node("Slice", ["obs", "s", "e", "ax"], ["stop"]),
            helper.make_node("Log", ["stop"], ["l"]),
            helper.make_node("Concat", ["l", "l", "l", "l"], ["action"], axis=1),
        ],
        "fails",
        [helper.make_tensor_value_info("obs", TensorProto.FLOAT, [1, 69])],
        [helper.make_tensor_value_info("action", TensorProto.FLOAT, [1, 4])],
        [numpy_helper.from_array(np.array(v, np.int64), k) for k, v in consts.items()],
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    return save_policy(path, {1: model}, base="BS")


def test_a_robot_whose_policy_fails_in_the_first_ticks_is_the_only_one_blamed(tmp_path):
    """Its process dies at tick 3; a peer still at the start barrier saw its token come and go, and does
    not wait 30 s for it and exit blaming it ("gave up waiting for robot/a/1")."""
    path = _fails_once_the_first_order_arrives(tmp_path / "fails.onnx")
    r = _arena("match", "--home", f"policy:{path}", "--away", "BS", "--half-time", "2", "--json")
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout)
    assert got["dead"] == ["robot/a/1"], r.stderr
    assert "gave up" not in r.stderr and "must be finite" in r.stderr
