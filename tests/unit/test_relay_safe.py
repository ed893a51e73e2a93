"""The launcher's own peers put towards the router with DROP (issue 20 item 6), and only towards it."""

from __future__ import annotations

import json

import zenoh

from arena.match.launcher import relay_safe
from arena.runtime.credentials import Secrets, load_fragment, new_zid

NAMES = ["engine", "referee", "basestation/a", "basestation/b", "robot/a/0", "robot/b/0"]


def test_a_peers_fragment_names_the_router_and_drops_only_puts_towards_it(tmp_path):
    zid = new_zid()
    assert len(zid) == 32 and zid[0] != "0" and int(zid, 16)
    s = Secrets.new("m1", 1, NAMES, secure=False)
    paths = s.write(tmp_path, {"engine": relay_safe(zid, "engine", "m1", 1, set())})
    [rule] = load_fragment(str(paths["engine"]))["qos"]["network"]
    assert rule["zids"] == [zid] and rule["flows"] == ["egress"] and rule["messages"] == ["put"]
    assert rule["overwrite"] == {"congestion_control": "drop"}
    assert "qos" not in load_fragment(str(paths["robot/a/0"]))  # e.g. an --external process: unchanged
    assert load_fragment(str(paths["engine"]))["metadata"] == s.fragment("engine")["metadata"]


def test_zenoh_takes_the_fragment_and_the_routers_id():
    zid = new_zid()
    frag = Secrets.new("m1", 1, NAMES, secure=False).fragment("engine") | relay_safe(
        zid, "engine", "m1", 1, {"robot/a/0"}
    )
    zenoh.Config.from_json5(json.dumps(frag))  # a wrong field would raise
    zenoh.Config().insert_json5("id", json.dumps(zid))


def test_what_an_external_process_receives_stays_block_towards_the_router():
    """An --external robot is a client: its sense, the field and the referee reach it through the router."""
    zid = new_zid()
    [rule] = relay_safe(zid, "engine", "m1", 1, {"robot/a/0"})["qos"]["network"]
    assert rule["zids"] == [zid] and rule["overwrite"] == {"congestion_control": "drop"}
    assert "arena/m1/robot/b/0/sense" in rule["key_exprs"] and "arena/m1/world" in rule["key_exprs"]
    assert "arena/m1/robot/a/0/sense" not in rule["key_exprs"] and "arena/m1/field" not in rule["key_exprs"]
    [rule] = relay_safe(zid, "referee", "m1", 1, {"robot/a/0"})["qos"]["network"]
    assert rule["key_exprs"] == ["arena/m1/summary/referee", "arena/m1/tap/referee"], "referee stays BLOCK"
    [rule] = relay_safe(zid, "basestation/a", "m1", 1, {"robot/a/0"})["qos"]["network"]
    assert "arena/m1/team/a/order/0" not in rule["key_exprs"]
    [rule] = relay_safe(zid, "engine", "m1", 1, set())["qos"]["network"]
    assert "key_exprs" not in rule, "no external: every put towards the router is DROP"


def viewer_rule(settings) -> dict:
    [value] = [v for k, v in settings if k == "qos/network"]
    [rule] = json.loads(value)
    return rule


def test_a_secure_router_opens_with_the_viewers_drop_rule(tmp_path):
    """In a secure match only what goes to the viewer is DROP (the viewer's fragment carries its id)."""
    from arena.runtime.session import NetConfig, open_session

    s = Secrets.new("m1", 1, NAMES, secure=True)
    settings = s.router_settings(tmp_path)
    rule = viewer_rule(settings)
    assert rule["zids"] == [s.viewer_zid] == [s.fragment("viewer")["id"]]
    assert rule["messages"] == ["put"] and rule["overwrite"] == {"congestion_control": "drop"}
    assert "id" not in s.fragment("engine"), "only the viewer's id is chosen for it"
    net = NetConfig(mode="router", listen=(f"unixsock-stream/{tmp_path}/r.sock",), extra=tuple(settings))
    with open_session(net):  # zenoh checks the rule's fields only here
        pass


def test_a_standalone_secure_router_serves_the_viewer_it_wrote_credentials_for_with_drop(tmp_path):
    """`arena run router --credentials DIR` (compose): the same rule, naming the id in DIR/viewer.json5."""
    from arena.match.router import secure_router
    from arena.runtime.session import NetConfig

    net = secure_router(
        "m1", NetConfig(mode="router", listen=(f"unixsock-stream/{tmp_path}/r.sock",)), str(tmp_path), tmp_path
    )
    rule = viewer_rule(net.extra)
    assert rule["zids"] == [load_fragment(str(tmp_path / "viewer.json5"))["id"]]
