"""`arena experiment run --ray` on a real two-node Ray cluster on this machine
(ray.cluster_utils.Cluster): the same file as locally, the same rows; a node lost mid-run."""

from __future__ import annotations

import json
import time

import pytest

from tests.integration.helpers import arena_json, cmdline, descendants, spawn, wait_for

ray = pytest.importorskip("ray", reason="the cluster extra: pip install -e '.[test,cluster]'")

FILE = """
seeds = 2
[base]
home = "AD"
away = "BS"
half_time = 5.0
[factors]
"rules.kickoff_time" = [1.0, 2.0]
"""


@pytest.fixture(scope="module")
def cluster():
    from ray.cluster_utils import Cluster

    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 2, "include_dashboard": False})
    try:
        c.add_node(num_cpus=2)
        c.wait_for_nodes()
        yield c
    finally:
        c.shutdown()


def rows(out) -> list[dict]:
    return [{k: v for k, v in r.items() if k != "cpu_s"} for r in json.loads((out / "rows.json").read_text())]


def test_the_same_file_on_ray_gives_the_same_rows(cluster, tmp_path):
    f = tmp_path / "exp.toml"
    f.write_text(FILE)
    local = arena_json("experiment", "run", str(f), "--out", str(tmp_path / "local"), "--jobs", "2")
    remote = arena_json("experiment", "run", str(f), "--out", str(tmp_path / "ray"), "--ray", cluster.address)
    assert local["matches"] == remote["matches"] == 8 and remote["failed"] == 0
    assert rows(tmp_path / "ray") == rows(tmp_path / "local")


def raylet_pid(node) -> int:
    from ray._private import ray_constants

    return node.all_processes[ray_constants.PROCESS_TYPE_RAYLET][0].process.pid


@pytest.mark.slow
def test_a_node_lost_mid_run_costs_no_row(cluster, tmp_path, reap):
    """A node dies while its tasks play: Ray runs them again on the other node; one row per match."""
    f = tmp_path / "exp.toml"
    f.write_text(FILE.replace("half_time = 5.0", "half_time = 20.0").replace("seeds = 2", "seeds = 4"))
    victim = cluster.add_node(num_cpus=2)
    cluster.wait_for_nodes()
    out = tmp_path / "ray"
    proc = spawn("experiment", "run", str(f), "--out", str(out), "--ray", cluster.address, "--json")
    reap.append(proc)
    wait_for(
        lambda: [p for p in descendants(raylet_pid(victim)) if "ray_task" in cmdline(p)],
        180,
        "a match to run on the node to be removed",
    )
    time.sleep(1.0)
    cluster.remove_node(victim, allow_graceful=False)
    stdout, stderr = proc.communicate(timeout=600)
    assert proc.returncode == 0, stderr[-3000:]
    summary = json.loads(stdout)
    assert summary["matches"] == 16 and summary["failed"] == 0
    ids = [r["match"] for r in json.loads((out / "rows.json").read_text())]
    assert len(ids) == len(set(ids)) == 16
