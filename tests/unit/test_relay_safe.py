"""The launcher's own peers put towards the router with DROP (issue 20 item 6), and only towards it."""

from __future__ import annotations

import json

import zenoh

from arena.runtime.credentials import Secrets, load_fragment
from arena.tools.launcher import new_zid, relay_safe

NAMES = ["engine", "referee", "basestation/a", "basestation/b", "robot/a/0", "robot/b/0"]


def test_a_peers_fragment_names_the_router_and_drops_only_puts_towards_it(tmp_path):
    zid = new_zid()
    assert len(zid) == 32 and zid[0] != "0" and int(zid, 16)
    s = Secrets.new("m1", 1, NAMES, secure=False)
    paths = s.write(tmp_path, {"engine": relay_safe(zid)})
    [rule] = load_fragment(str(paths["engine"]))["qos"]["network"]
    assert rule["zids"] == [zid] and rule["flows"] == ["egress"] and rule["messages"] == ["put"]
    assert rule["overwrite"] == {"congestion_control": "drop"}
    assert "qos" not in load_fragment(str(paths["robot/a/0"]))  # e.g. an --external process: unchanged
    assert load_fragment(str(paths["engine"]))["metadata"] == s.fragment("engine")["metadata"]


def test_zenoh_takes_the_fragment_and_the_routers_id():
    zid = new_zid()
    frag = Secrets.new("m1", 1, NAMES, secure=False).fragment("engine") | relay_safe(zid)
    zenoh.Config.from_json5(json.dumps(frag))  # a wrong field would raise
    zenoh.Config().insert_json5("id", json.dumps(zid))


def test_a_secure_router_opens_with_the_viewers_drop_rule(tmp_path):
    """In a secure match only what goes to the viewer is DROP (the viewer's fragment carries its id)."""
    from arena.runtime.session import NetConfig, open_session
    from arena.tools.launcher import viewer_safe

    path, value = viewer_safe(new_zid())
    [rule] = json.loads(value)
    assert path == "qos/network" and rule["messages"] == ["put"] and rule["overwrite"] == {"congestion_control": "drop"}
    net = NetConfig(mode="router", listen=(f"unixsock-stream/{tmp_path}/r.sock",), extra=((path, value),))
    with open_session(net):  # zenoh checks the rule's fields only here
        pass
