"""The fork server (match/zygote.py): every match of a long-lived process starts forked, nothing is orphaned."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

from tests.integration.helpers import alive, wait_for

# A process that plays match after match, as `arena bench match` does: only its
# first match could fork without the zygote (it opens zenoh for that match's router).
PLAYER = textwrap.dedent(
    """
    import json, os, sys
    from arena.config import MatchConfig
    from arena.match import launcher, zygote

    z = zygote.start(ready=10)
    out = []
    for launch in ("zygote", "zygote", "exec"):
        if launch == "exec":
            os.environ["ARENA_LAUNCH"] = "exec"
        cfg = MatchConfig(seed=7, home="AD", away="BS", robots=3, half_time=1.0)
        r = launcher.play_match(cfg).to_dict()
        out.append({k: r[k] for k in ("launch", "digest", "process_digests", "outcome", "startup_seconds")})
        out[-1]["pids"] = sorted(p["pid"] for p in r["processes"] if p["pid"])
    print(json.dumps({"zygote": z.pid, "matches": out}))
    """
)


def test_every_match_of_a_long_lived_process_is_forked_with_the_same_digests():
    r = subprocess.run([sys.executable, "-c", PLAYER], capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stderr[-3000:]
    got = json.loads(r.stdout)
    first, second, execd = got["matches"]
    assert [m["launch"] for m in got["matches"]] == ["zygote", "zygote", "exec"]
    assert all(m["outcome"] == "completed" for m in got["matches"])
    assert first["process_digests"] == second["process_digests"] == execd["process_digests"]
    assert first["startup_seconds"] is not None and second["startup_seconds"] is not None
    assert set(first["pids"]).isdisjoint(second["pids"]), "each match gets children of its own"
    # The launcher's exit ends the zygote and the children it had parked for a next match.
    wait_for(lambda: not alive(got["zygote"]), 10, "the zygote to exit with its launcher")


PARKED = textwrap.dedent(
    """
    import json, time
    from arena.match import zygote

    z = zygote.start(ready=4)
    print(json.dumps([z.pid, *[pid for pid, _ in z._parked]]), flush=True)
    time.sleep(120)
    """
)


def test_a_killed_launcher_leaves_no_zygote_and_no_parked_child(reap):
    proc = subprocess.Popen([sys.executable, "-c", PARKED], stdout=subprocess.PIPE, text=True)
    reap.append(proc)
    pids = json.loads(proc.stdout.readline())
    assert len(pids) == 5 and all(alive(p) for p in pids)
    proc.kill()
    proc.wait()
    wait_for(lambda: not [p for p in pids if alive(p)], 10, "the zygote and parked children to exit")
