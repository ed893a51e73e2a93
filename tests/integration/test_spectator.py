"""Issue 20 item 6: a spectator cannot hurt a match.

A zenoh client subscribed to `arena/<m>/**` of a recorded match through the
match's router, with a callback far slower than the match (it sleeps on
every sample), while the router falls behind three times (the launcher,
which hosts it, is stopped for 0.3 s, as a loaded host does to it).

With a spectator on `**` every peer also puts every frame towards the router.
When the router fell behind, a peer's queue towards it filled, and a put made
in a zenoh callback (reactive nodes put there) waited on zenoh's only thread
of that process, the one that would have written the queue out: for 5 s
(`wait_before_close`), then zenoh closed the link and the router saw the
engine's token vanish (a fault; in 3 of ~11 earlier runs, and in every run
with these pauses). The launcher's own peers now put towards the router with
congestion control DROP (`relay_safe` in match/launcher.py), and the router
relays to clients with DROP, so the spectator only loses frames. The match
must complete whatever the spectator does; no timing is asserted.
"""

from __future__ import annotations

import os
import signal
import threading
import time

from arena.runtime.session import NetConfig, open_session
from tests.integration.helpers import spawn, wait_for
from tests.integration.test_faults import finish


def hiccups(match, started: threading.Event, done: threading.Event) -> None:
    """Stop the router's process 3 times for 0.3 s once the match plays (a router behind the peers)."""
    started.wait(60)
    for _ in range(3):
        if done.is_set() or match.returncode is not None:
            return
        try:
            os.kill(match.pid, signal.SIGSTOP)
        except ProcessLookupError:
            return
        time.sleep(0.3)
        try:
            os.kill(match.pid, signal.SIGCONT)
        except ProcessLookupError:  # the match ended while it was stopped
            return
        done.wait(0.5)


def test_a_slow_spectator_on_everything_of_a_recorded_match_does_not_hurt_it(tmp_path, reap):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    record = tmp_path / "match.mcap"
    match = spawn("match", "--home", "BS", "--away", "BS", "--half-time", "10", "--seed", "4",
                  "--match", "spectated", "--listen", endpoint, "--record", str(record), "--json")  # fmt: skip
    reap.append(match)
    wait_for(lambda: (tmp_path / "router.sock").exists(), 60, "the router socket")
    seen = [0]
    started, done = threading.Event(), threading.Event()

    def slow(sample) -> None:
        seen[0] += 1
        if seen[0] == 20:
            started.set()
        time.sleep(0.005)  # far slower than the match: every queue towards it fills up

    pauser = threading.Thread(target=hiccups, args=(match, started, done), daemon=True)
    pauser.start()
    try:
        with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
            sub = session.declare_subscriber("arena/spectated/**", slow)
            code, result, err = finish(match, 240)
            sub.undeclare()
    finally:
        done.set()
        started.set()
        pauser.join()
    assert code == 0, err
    assert result["outcome"] == "completed", result["outcome_reasons"]
    assert result["dead"] == [] and result["ticks"] == 1000
    assert result["recording"]["complete"], result["recording"]
    assert seen[0] > 0, "the spectator did receive frames"
