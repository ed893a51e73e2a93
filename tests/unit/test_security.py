"""The access control generated from the key table, the credentials files, and the MAC."""

from __future__ import annotations

import hashlib
import json

import pytest

from arena.runtime.acl import access_control, permissions, principals
from arena.runtime.credentials import Secrets, load_fragment
from arena.runtime.mac import Keyring, tag
from arena.schemas.keys import process_names

P = "arena/m/"
NAMES = process_names(3)


def _rel(keys: list[str]) -> set[str]:
    return {k[len(P) :] for k in keys}


def test_robot_a1_puts_only_on_its_cmd_and_report():
    perms = permissions("robot/a/1", P, 3)
    assert _rel(perms["put/ingress"]) == {
        "robot/a/1/cmd",
        "team/a/report/1",
        "summary/robot/a/1",
        "tap/robot/a/1",
        "refused/robot/a/1",
    }
    # the referee state is public (a RefBox broadcasts it to every team)
    assert _rel(perms["declare_subscriber/ingress"]) == {
        "robot/a/1/sense",
        "team/a/order/1",
        "field",
        "referee",
        "ack/robot/a/1",
    }
    # its liveliness, and the tokens that announce its long lockstep waits (runtime/drivers.py Reactor)
    # ... the token that holds its identity (one process per identity: match/claims.py), and the
    # tokens that say it saw forged or conflicting frames on a key (the launcher prints them)
    assert _rel(perms["liveliness_token/ingress"]) == {
        "alive/robot/a/1",
        "waiting/robot/a/1/*",
        "claim/robot/a/1/*",
        "spoofing/robot-a-1/**",
    }
    assert "claim/robot/a/1" in _rel(perms["query/ingress"]) and "claim/robot/a/2" not in _rel(perms["query/ingress"])


def test_team_b_never_reads_team_a_nor_the_world():
    for p in [n for n in NAMES if "/b" in n]:
        reads = _rel(permissions(p, P, 3)["declare_subscriber/ingress"]) | _rel(permissions(p, P, 3)["put/egress"])
        assert not any(k.startswith(("team/a/", "robot/a/")) for k in reads), p
        assert "world" not in reads and "engine/events" not in reads, p
        writes = _rel(permissions(p, P, 3)["put/ingress"])
        assert not any("/a/" in k for k in writes) and "referee" not in writes, p


def test_the_viewer_reads_world_referee_and_field_and_writes_no_match_data():
    perms = permissions("viewer", P, 3)
    assert {"world", "referee", "field"} <= _rel(perms["declare_subscriber/ingress"])
    # read-only: nothing of the match's data, only its own infrastructure keys and the live control
    assert _rel(perms["put/ingress"]) == {"summary/viewer", "tap/viewer", "refused/viewer", "control"}


def test_default_deny_and_one_policy_per_principal():
    acl = access_control(P, 3, NAMES)
    assert acl["enabled"] and acl["default_permission"] == "deny"
    assert {s["id"] for s in acl["subjects"]} == {n.replace("/", "-") for n in NAMES} | {"viewer", "operator"}
    ids = [r["id"] for r in acl["rules"]]
    assert len(ids) == len(set(ids))
    assert all(r["key_exprs"] and all(k.startswith(P) for k in r["key_exprs"]) for r in acl["rules"])


def test_fragments_hold_user_password_tls_root_and_keys(tmp_path):
    s = Secrets.new("m1", 3, NAMES, secure=True, tls=True)
    paths = s.write(tmp_path)
    assert paths["robot/b/1"].name == "robot-b-1.json5" and paths["viewer"].name == "viewer.json5"
    frag = load_fragment(str(paths["robot/b/1"]))
    assert frag["mode"] == "client"
    assert frag["transport"]["auth"]["usrpwd"]["user"] == "robot-b-1"
    assert frag["transport"]["link"]["tls"]["root_ca_certificate_base64"]
    keys = frag["metadata"]["arena"]["keys"]
    # Its own key, and the keys of the senders of what it receives (sense, field; its orders): every
    # frame it takes is authenticated, in every mode. No other robot's, no other team's.
    assert set(keys) == {"robot/b/1", "engine", "basestation/b"}
    # the referee takes a live session's operator frames, the engine those and the viewer's control frames
    assert set(load_fragment(str(paths["referee"]))["metadata"]["arena"]["keys"]) == {"referee", "engine", "operator"}
    bs = set(load_fragment(str(paths["basestation/a"]))["metadata"]["arena"]["keys"])
    assert bs == {"basestation/a", "engine", "referee", "robot/a/0", "robot/a/1", "robot/a/2"}  # field: engine
    engine = set(load_fragment(str(paths["engine"]))["metadata"]["arena"]["keys"])
    assert engine == {"engine", "referee", "viewer", "operator", *(f"robot/{t}/{n}" for t in "ab" for n in range(3))}
    viewer = set(load_fragment(str(paths["viewer"]))["metadata"]["arena"]["keys"])
    assert "operator" not in viewer, "the operator's key is lent to a local viewer only (match/launcher.py)"
    lent = s.keyring("viewer", ("operator",))
    assert lent.signer("arena/m1/operator", sender="operator") is not None and lent.own == s.mac_keys["viewer"]
    insecure = Secrets.new("m1", 3, NAMES, secure=False).fragment("robot/b/1")
    assert set(insecure) == {"metadata"}, "without --secure: the MAC key only, the zenoh settings untouched"
    json.dumps(frag)  # plain JSON, so valid JSON5


def test_the_mac_is_keyed_blake2b_over_key_nul_payload():
    key = bytes(range(32))
    expected = hashlib.blake2b(b"arena/m/summary/engine\0\x81\xa1a\x01", key=key, digest_size=16).digest()
    assert tag(key, "arena/m/summary/engine", b"\x81\xa1a\x01") == expected
    # The test vector of schemas/README.md (Security):
    assert expected.hex() == "d7c51f4829d4546d963595dcd996ee3f"
    ring = Keyring("referee", {"engine": key})
    ok = ring.verifier("engine", "arena/m/engine/events")
    payload = b"\x82"
    assert ok(payload, tag(key, "arena/m/engine/events", payload))
    assert not ok(payload, None) and not ok(payload, tag(key, "arena/m/referee", payload))
    assert ring.verifier("robot/a/1", "arena/m/summary/robot/a/1") is None  # no key: accepted as before


def test_a_signer_and_a_verifier_reused_frame_after_frame_give_exactly_tag():
    """They hash the key and the key expression once and copy that state per frame: no state may leak
    from one frame into the next, and each stays bound to its own key expression."""
    key = bytes(range(32))
    ring = Keyring("engine", {"engine": key})
    sign = ring.signer("arena/m/engine/events")
    ok = ring.verifier("engine", "arena/m/engine/events")
    other = ring.signer("arena/m/world")
    for payload in (b"", b"\x82", b"\x82" * 5000, b"\x00\x01", b""):
        assert sign(payload) == tag(key, "arena/m/engine/events", payload)
        assert other(payload) == tag(key, "arena/m/world", payload) != sign(payload)
        assert ok(payload, sign(payload)) and not ok(payload, other(payload)) and not ok(payload + b"x", sign(payload))


class _Bytes:
    def __init__(self, raw: bytes):
        self.raw = raw

    def to_bytes(self) -> bytes:
        return self.raw


class _Sample:  # what a zenoh callback reads of a sample: payload and attachment
    def __init__(self, payload: bytes, attachment: bytes | None):
        self.payload = _Bytes(payload)
        self.attachment = None if attachment is None else _Bytes(attachment)


def test_the_transports_signed_put_and_verified_callback_work_out_exactly_tag():
    """runtime/transport.py tags and checks inline (the keyed prefix copied in its own frame): every
    frame carries exactly `tag`; a missing or wrong MAC is forged, a local WAKE passes."""
    from arena.runtime.transport import WAKE, _on_sample, _signed

    key, expr = bytes(range(32)), "arena/m/robot/a/0/cmd"
    ring = Keyring("engine", {"robot/a/0": key})
    sent: list[tuple[bytes, bytes]] = []
    put = _signed(
        lambda p, attachment: sent.append((p, attachment)), Keyring("robot/a/0", {"robot/a/0": key}).signer(expr)
    )
    got: list[bytes] = []
    forged: list[int] = []
    on_sample = _on_sample(got.append, ring.verifier("robot/a/0", expr), lambda: forged.append(1))
    for payload in (b"\x82" * 300, b"", b"\x81\xa1a\x01"):
        put(payload)
        assert sent[-1] == (payload, tag(key, expr, payload))
        on_sample(_Sample(*sent[-1]))
        assert got[-1] == payload and not forged
    for attachment in (None, tag(key, "arena/m/robot/a/1/cmd", b"\x82"), tag(bytes(32), expr, b"\x82")):
        on_sample(_Sample(b"\x82", attachment))
    assert len(forged) == 3 and len(got) == 3
    on_sample(_Sample(WAKE, None))
    assert got[-1] == WAKE and len(forged) == 3
    # A verifier that is not runtime/mac.py's is asked as it is.
    plain = _on_sample(got.append, lambda p, a: a == b"ok", lambda: forged.append(1))
    plain(_Sample(b"x", b"ok"))
    plain(_Sample(b"y", b"no"))
    assert got[-1] == b"x" and len(forged) == 4


def test_only_the_operator_puts_operator_frames_and_only_the_engine_and_referee_read_them():
    key = f"{P}operator"
    puts = {p for p in principals(NAMES) if key in permissions(p, P, 3).get("put/ingress", [])}
    reads = {p for p in principals(NAMES) if key in permissions(p, P, 3).get("declare_subscriber/ingress", [])}
    assert puts == {"operator"} and reads == {"engine", "referee"}
    op = permissions("operator", P, 3)
    assert op["put/ingress"] == [key] and not any("/alive/" in k for k in op.get("liveliness_token/ingress", []))


@pytest.mark.parametrize("lent", [False, True])
def test_the_viewer_forwards_foxglove_operator_messages_only_with_the_operators_key(lent):
    """A Foxglove client published `/operator` and the viewer put it as is: a stranger's goal counted.
    Only a viewer started for a local operator holds the operator's key (match/launcher.py
    `local_operator`) and signs with it; any other refuses the message, counted."""
    from arena.config import MatchConfig, ProcessId
    from arena.processes.viewer import ViewerNode
    from arena.runtime.mac import Keyring, new_key
    from arena.runtime.transport import MemoryBus, MemoryTransport
    from arena.schemas.keys import Keys

    bus = MemoryBus()
    tr = MemoryTransport(bus)
    tr.keyring = Keyring("viewer", {"viewer": new_key(), **({"operator": new_key()} if lent else {})})
    engine_side = MemoryTransport(bus).subscribe("arena/m/operator")
    viewer = ViewerNode(ProcessId("viewer"), MatchConfig(live=0, pace=1.0), tr, Keys("m"))
    try:
        viewer.on_client_message("/operator", b'{"actions": [{"type": "referee", "command": "GOAL", "team": "b"}]}')
    finally:
        viewer.server.stop()
    got = engine_side.try_recv()
    if lent:
        assert got is not None and viewer.rejections.total == 0
        assert viewer.operator_sign is not None
    else:
        assert got is None and viewer.rejections.by_reason == {"refused": 1}


def test_only_a_viewer_started_here_on_loopback_without_secure_is_lent_the_operators_key():
    from arena.config import MatchConfig, ProcessId
    from arena.match.launcher import local_operator

    live = MatchConfig(live=8765)
    assert local_operator(live, False, "127.0.0.1", set())
    assert local_operator(live, False, "::1", set())
    assert not local_operator(live, True, "127.0.0.1", set()), "secure: only the operator principal may put"
    assert not local_operator(live, False, "0.0.0.0", set()), "anybody on the network could publish"
    assert not local_operator(live, False, "127.0.0.1", {ProcessId("viewer")}), "a viewer started elsewhere"
    assert not local_operator(MatchConfig(), False, "127.0.0.1", set()), "no viewer"
