"""`arena tournament --ray` on a real multi-node Ray cluster on this machine (ray.cluster_utils.Cluster).

Two nodes, the head and one worker, each a separate raylet with its own
worker processes and 2 CPUs: one distributed-engine match at a time each. The tournament
runs as a separate `arena` process that joins the cluster by its address.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

from tests.integration.helpers import ARENA, arena_json, cmdline, descendants, spawn, wait_for

ray = pytest.importorskip("ray", reason="the cluster extra: pip install -e '.[test,cluster]'")


@pytest.fixture(scope="module")
def cluster():
    from ray.cluster_utils import Cluster

    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 2, "include_dashboard": False})
    try:
        workers = [c.add_node(num_cpus=2)]
        c.wait_for_nodes()
        yield c, workers
    finally:
        c.shutdown()


def tournament(*extra: str) -> tuple[str, ...]:
    return ("tournament", "--legs", "1", "--half-time", "10", "--seed", "3", *extra)


def at_once(*commands: tuple[str, ...]) -> list[dict]:
    """`arena_json` of each command, all running at the same time (each is its own `arena` process,
    and much of a Ray tournament is waiting on Ray); the results in the order given."""
    with ThreadPoolExecutor(max_workers=len(commands)) as pool:
        return list(pool.map(lambda args: arena_json(*args), commands))


def digests(summary: dict) -> dict[str, str]:
    return {m["id"]: m["digest"] for m in summary["matches"]}


def check_tables(summary: dict, matches_each: int) -> None:
    assert summary["failed"] == [] and all(m["status"] == "ok" for m in summary["matches"])
    ids = [m["id"] for m in summary["matches"]]
    assert len(ids) == len(set(ids))
    for row in summary["table"]:
        assert row["W"] + row["D"] + row["L"] == matches_each, row
        assert row["P"] == 3 * row["W"] + row["D"]
    assert sum(r["GF"] for r in summary["table"]) == sum(r["GA"] for r in summary["table"])
    goals = sum(sum(m["score"]) for m in summary["matches"])
    assert sum(r["GF"] for r in summary["table"]) == goals


def test_two_nodes_same_digests_as_local_jobs(cluster, tmp_path):
    """Fast: 2 matches, one per node, with either engine; digests equal to the local run's."""
    c, _ = cluster
    args = tournament("--strategies", "BS,AD", "--legs", "2", "--half-time", "5")
    local, remote, inproc = at_once(
        (*args, "--jobs", "2", "--out", str(tmp_path / "local")),
        (*args, "--ray", c.address, "--out", str(tmp_path / "ray")),
        (*args, "--ray", c.address, "--engine", "inprocess", "--out", str(tmp_path / "inproc")),
    )
    assert digests(remote) == digests(local) == digests(inproc) and len(digests(local)) == 2
    assert {m["engine"] for m in inproc["matches"]} == {"inprocess"}
    check_tables(remote, 2)
    check_tables(inproc, 2)
    logs = [(tmp_path / "ray" / "logs" / f"{m['id']}.log").read_text() for m in remote["matches"]]
    assert all("played on node" in text for text in logs)
    saved = json.loads((tmp_path / "ray" / "tournament.json").read_text())
    assert saved["table"] == remote["table"]


SIX = tournament("--strategies", "AD,AS,BD,BS")


@pytest.fixture(scope="module")
def local_six(tmp_path_factory):
    """The 6-match round-robin played with local jobs, once for the tests that compare with it."""
    return arena_json(*SIX, "--jobs", "2", "--out", str(tmp_path_factory.mktemp("local")))


@pytest.mark.slow
def test_six_match_round_robin_equals_local(cluster, local_six, tmp_path):
    c, _ = cluster
    local = local_six
    remote = arena_json(*SIX, "--ray", c.address, "--out", str(tmp_path / "ray"))
    assert len(digests(local)) == 6
    assert digests(remote) == digests(local)
    assert remote["table"] == local["table"]
    check_tables(remote, 3)


def raylet_pid(node) -> int:
    from ray._private import ray_constants

    return node.all_processes[ray_constants.PROCESS_TYPE_RAYLET][0].process.pid


@pytest.mark.slow
def test_worker_node_removed_mid_task(cluster, local_six, tmp_path, reap):
    """A node dies while its match plays: Ray reruns the task on the other node; every match counted once."""
    c, workers = cluster
    victim = c.add_node(num_cpus=2)  # the fixture's nodes stay for the other tests
    c.wait_for_nodes()
    out = tmp_path / "ray"
    proc = spawn(*SIX, "--ray", c.address, "--out", str(out), "--json")
    reap.append(proc)
    on_victim = wait_for(
        lambda: [p for p in descendants(raylet_pid(victim)) if " arena match " in cmdline(p)],
        120,
        "a match to run on the node to be removed",
    )
    time.sleep(1.0)  # well inside the match (10 s halves take several seconds)
    argv = cmdline(on_victim[0]).split()
    killed = (argv[argv.index("--home") + 1], argv[argv.index("--away") + 1], int(argv[argv.index("--seed") + 1]))
    c.remove_node(victim, allow_graceful=False)
    wait_for(lambda: not any(" arena match " in cmdline(p) for p in on_victim), 20, "the match to die with its node")
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr[-3000:]
    summary = json.loads(stdout)
    assert len(summary["matches"]) == 6
    check_tables(summary, 3)
    assert len(list((out / "matches").glob("*.json"))) == 6
    assert digests(summary) == digests(local_six)
    assert summary["table"] == local_six["table"]
    (replayed,) = [m for m in summary["matches"] if (m["home"], m["away"], m["seed"]) == killed]
    assert replayed["attempts"] == 1, "a node's death is Ray's retry, not a second attempt of the match"
    log = (out / "logs" / f"{replayed['id']}.log").read_text()
    assert "played on node" in log and victim.node_id[:12] not in log, log
    assert "Traceback" not in stderr


def test_ray_alone_starts_a_local_instance_and_stops_it(tmp_path):
    args = ("tournament", "--strategies", "BS,AD", "--legs", "1", "--half-time", "2", "--engine", "inprocess")
    summary, local = at_once(
        (*args, "--jobs", "1", "--ray", "--out", str(tmp_path / "ray")),
        (*args, "--jobs", "1", "--out", str(tmp_path / "local")),
    )
    assert digests(summary) == digests(local) and len(digests(local)) == 1
    assert "played on node" in (tmp_path / "ray" / "logs" / f"{summary['matches'][0]['id']}.log").read_text()


def test_no_cluster_at_address_is_one_line_and_exit_2(tmp_path):
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # closed again below: nothing listens there
    t0 = time.monotonic()
    r = subprocess.run(
        [*ARENA, *tournament("--strategies", "BS,AD", "--ray", f"127.0.0.1:{port}", "--out", str(tmp_path))],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert time.monotonic() - t0 < 30
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and f"127.0.0.1:{port}" in lines[0] and "no Ray cluster" in lines[0], r.stderr
    for argv, says in (
        (["--ray", "nowhere"], "HOST:PORT"),
        (["--ray", "--ray-runtime-env", "{pip"], "not JSON"),
        (["--ray", "--ray-runtime-env", "[1]"], "JSON object"),
        (["--ray-runtime-env", "{}"], "needs --ray"),
    ):
        bad = subprocess.run([*ARENA, "tournament", *argv], capture_output=True, text=True, timeout=60)
        assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and says in bad.stderr, bad.stderr


def test_worker_with_another_version_refuses(cluster):
    """The real task on a real worker compares its own soccer-arena with what the driver says it has."""
    c, _ = cluster
    script = f"""
import json, ray
from arena.experiments import cluster
ray.init(address={c.address!r}, logging_level="ERROR", log_to_driver=False)
task = ray.remote(cluster.play_on_worker).options(num_cpus=1)
mine = cluster.fingerprint()
other = dict(mine, version="0.0.9", git="0123456789ab")
same = ray.get(ray.remote(cluster.fingerprint).options(num_cpus=1).remote())
bad = ray.get(task.remote({{"argv": ["-c", "print(1)"], "timeout": 30}}, other))
print(json.dumps({{"mine": mine, "same": same, "bad": bad}}))
ray.shutdown()
"""
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]
    got = json.loads(r.stdout.strip().splitlines()[-1])
    assert got["same"] == got["mine"], "a worker on this machine has the driver's soccer-arena"
    reason = got["bad"]["reason"]
    assert got["bad"]["rc"] != 0 and "version mismatch" in reason
    assert "0.0.9 (git 0123456789ab" in reason and f"{got['mine']['version']} (git {got['mine']['git']}" in reason


def test_without_ray_flag_ray_is_never_imported(tmp_path):
    script = f"""
import sys
from arena.cli import main
code = main(["tournament", "--strategies", "BS,AD", "--legs", "1", "--half-time", "1", "--jobs", "1",
             "--out", {str(tmp_path)!r}, "--json"])
assert code == 0, code
assert "ray" not in sys.modules and "arena.experiments.cluster" not in sys.modules, "Ray was imported"
"""
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_interrupt_cancels_tasks_keeps_results_then_resume(cluster, tmp_path, reap, sig):
    c, _ = cluster
    args = tournament("--strategies", "BS,AD,AS", "--half-time", "5", "--ray", c.address, "--out", str(tmp_path))
    proc = spawn(*args)
    reap.append(proc)
    matches = tmp_path / "matches"
    wait_for(lambda: matches.is_dir() and any(matches.glob("*.json")), 120, "the first finished match")
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "--resume" in err and "Traceback" not in err, err
    raylets = [raylet_pid(n) for n in (c.head_node, *c.worker_nodes)]
    wait_for(
        lambda: not any(" arena match " in cmdline(p) for r in raylets for p in descendants(r)),
        30,
        "the cancelled tasks' matches to stop",
    )
    kept = sorted(p.name for p in matches.glob("*.json"))
    assert 1 <= len(kept) < 3 and not list(matches.glob("*.tmp")), (kept, err)
    summary = arena_json(*args, "--resume")
    assert summary["skipped"] == len(kept) and len(summary["matches"]) == 3
    check_tables(summary, 2)


@pytest.mark.slow
def test_runtime_env_with_another_version_fails_naming_both(tmp_path):
    """A real pip runtime_env gives the workers a wheel of version 0.0.9: every match fails, naming both versions."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    src = tmp_path / "src"
    src.mkdir()
    archive = subprocess.run(["git", "-C", str(root), "archive", "HEAD"], capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
    pyproject = src / "pyproject.toml"
    pyproject.write_text(pyproject.read_text().replace('version = "0.1.0"', 'version = "0.0.9"'))
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels), str(src)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    (wheel,) = wheels.glob("soccer_arena-0.0.9-*.whl")
    env = json.dumps({"pip": [str(wheel)]})
    args = ("tournament", "--strategies", "BS,AD", "--legs", "1", "--half-time", "2", "--jobs", "1")
    out = tmp_path / "out"
    # Run outside the checkout: Ray puts the driver's working directory on the workers' sys.path.
    r = subprocess.run(
        [*ARENA, *args, "--ray", "--ray-runtime-env", env, "--out", str(out), "--json"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    assert "Traceback" not in r.stderr, r.stderr[-3000:]
    summary = json.loads(r.stdout)
    (failed,) = summary["failed"]
    mine = json.loads(
        subprocess.run(
            [
                sys.executable,
                "-c",
                "import json; from arena.experiments import cluster; print(json.dumps(cluster.fingerprint()))",
            ],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    )
    assert "version mismatch" in failed["reason"]
    assert "the worker has soccer-arena 0.0.9 (git none" in failed["reason"]
    assert (
        f"the driver has soccer-arena {mine['version']} (git {mine['git']}, source {mine['source']})"
        in failed["reason"]
    )
    assert summary["matches"][0]["attempts"] == 2
