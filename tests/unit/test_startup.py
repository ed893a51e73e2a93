"""Start-up of a distributed match: what keeps it short (docs/performance.md, session 6)."""

from arena.runtime.session import NetConfig


def test_a_lone_router_does_not_sleep_before_it_starts():
    # zenoh sleeps `scouting/delay` (500 ms by default) while a router starts; ours has
    # nothing to scout or connect to, so it must not wait.
    lone = NetConfig(mode="router", listen=("unixsock-stream/x.sock",)).zenoh_config()
    assert lone.get_json("scouting/delay") == "0"
    # A router that connects to others keeps zenoh's delay to do so.
    linked = NetConfig(mode="router", listen=("tcp/127.0.0.1:0",), connect=("tcp/127.0.0.1:7447",)).zenoh_config()
    assert linked.get_json("scouting/delay") != "0"
    peer = NetConfig(mode="peer", connect=("unixsock-stream/x.sock",)).zenoh_config()
    assert peer.get_json("scouting/delay") != "0"
