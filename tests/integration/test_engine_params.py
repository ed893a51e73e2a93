"""A strategy parameter reaches both engines alike: it changes the digest, and the two engines agree."""

from __future__ import annotations

from tests.integration.helpers import arena_json


def test_a_strategy_parameter_changes_the_digest_alike_on_both_engines():
    base = ("match", "--home", "AD", "--away", "BS", "--half-time", "20", "--seed", "1", "--json")
    plain = arena_json(*base, "--engine", "inprocess")
    got = {e: arena_json(*base, "--engine", e, "--param", "a.kick_speed=6.0") for e in ("processes", "inprocess")}
    assert got["processes"]["digest"] == got["inprocess"]["digest"] != plain["digest"]
    assert got["processes"]["process_digests"] == got["inprocess"]["process_digests"]
    assert got["processes"]["params"] == got["inprocess"]["params"] == {"a": {"kick_speed": 6.0}}
