"""A tournament on a Ray cluster of N nodes on this one machine: docs/cluster.md quotes its output.

    pip install -e '.[cluster]'
    python examples/cluster_nodes.py --nodes 1 2 1 2 -- --strategies AD,AS,BD,BS --legs 2 --half-time 30

For each entry of --nodes (run in that order, so 1 and 2 interleave) it starts
a fresh `ray.cluster_utils.Cluster` whose nodes share the machine's cores
(the head plus N-1 workers; the logical CPUs are split evenly so that the
same number of matches runs at once whatever N), runs `arena tournament
--ray ADDRESS --json` with the arguments after `--`, and prints the
tournament's own wall time, the nodes that played, and the digests' hash.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path


def one(nodes: int, cpus: int, tournament: list[str]) -> None:
    from ray.cluster_utils import Cluster

    c = Cluster(initialize_head=True, head_node_args={"num_cpus": cpus // nodes, "include_dashboard": False})
    try:
        for _ in range(nodes - 1):
            c.add_node(num_cpus=cpus // nodes)
        c.wait_for_nodes()
        with tempfile.TemporaryDirectory() as out:
            argv = [sys.executable, "-m", "arena", "tournament", *tournament, "--ray", c.address, "--out", out]
            r = subprocess.run([*argv, "--json"], capture_output=True, text=True, check=True)
            s = json.loads(r.stdout)
            where = Counter(
                line.split()[-1]
                for log in Path(out, "logs").glob("0*.log")
                for line in log.read_text().splitlines()
                if "played on node" in line
            )
        digests = hashlib.blake2b("".join(m["digest"] for m in s["matches"]).encode(), digest_size=6).hexdigest()
        ok = sum(m["status"] == "ok" for m in s["matches"])
        print(
            f"nodes={nodes} wall={s['wall_seconds']:.1f} s matches_ok={ok}/{len(s['matches'])} "
            f"per_node={sorted(where.values())} digests={digests}",
            flush=True,
        )
    finally:
        c.shutdown()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--nodes", type=int, nargs="+", default=[1, 2], help="node counts, run in this order")
    p.add_argument("--cpus", type=int, default=4, help="logical CPUs of the whole cluster (4: two matches at once)")
    p.add_argument("tournament", nargs=argparse.REMAINDER, help="-- then arena tournament's arguments")
    a = p.parse_args()
    rest = a.tournament[1:] if a.tournament[:1] == ["--"] else a.tournament
    for n in a.nodes:
        one(n, a.cpus, rest)


if __name__ == "__main__":
    main()
