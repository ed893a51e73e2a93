"""Issue 20 item 6: a spectator cannot hurt a match.

A zenoh client subscribed to `arena/<m>/**` of a recorded match through the
match's router, with a callback far slower than the match (it sleeps on
every sample), used to stall the match for 5-6 s at a time (the router
waited on it under congestion control BLOCK), long enough for leases to
lapse and the match to be void. The match must complete whatever the
spectator does; no timing is asserted.

Opt-in (-m slow): the router's DROP relay and transmit thread made the stall
rarer, not impossible. On a loaded 2-core host the engine's lease still lapsed
in some runs (3 of about 11 so far), so issue 20 stays open on item 6.
"""

from __future__ import annotations

import time

import pytest

from arena.runtime.session import NetConfig, open_session
from tests.integration.helpers import spawn, wait_for
from tests.integration.test_faults import finish


@pytest.mark.slow
def test_a_slow_spectator_on_everything_of_a_recorded_match_does_not_hurt_it(tmp_path, reap):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    record = tmp_path / "match.mcap"
    match = spawn("match", "--home", "BS", "--away", "BS", "--half-time", "10", "--seed", "4",
                  "--match", "spectated", "--listen", endpoint, "--record", str(record), "--json")  # fmt: skip
    reap.append(match)
    wait_for(lambda: (tmp_path / "router.sock").exists(), 60, "the router socket")
    seen = [0]

    def slow(sample) -> None:
        seen[0] += 1
        time.sleep(0.005)  # far slower than the match: every queue towards it fills up

    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        sub = session.declare_subscriber("arena/spectated/**", slow)
        code, result, err = finish(match, 240)
        sub.undeclare()
    assert code == 0, err
    assert result["outcome"] == "completed", result["outcome_reasons"]
    assert result["dead"] == [] and result["ticks"] == 1000
    assert result["recording"]["complete"], result["recording"]
    assert seen[0] > 0, "the spectator did receive frames"
