"""Start-up of a distributed match: what keeps it short (docs/performance.md)."""

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


def test_bench_throughput_reports_both_start_ups_with_their_definitions():
    from arena.experiments import throughput

    def run(rtf, command, play_match):
        return {
            "rtf": rtf,
            "sim_seconds": 120.0,
            "command_wall_s": 3.0,
            "command_cpu_s": 6.0,
            "launch_to_first_tick_s": command,
            "play_match_to_first_tick_s": play_match,
            "launch": "fork",
            "overhead_s": 0.5,
        }

    s = throughput.summarise([run(40, 0.6, 0.3), run(50, 0.5, 0.2), run(45, 0.7, 0.25)], jobs=2, cores=2)
    assert s["launch_to_first_tick_s"] == 0.6 and s["play_match_to_first_tick_s"] == 0.25
    assert s["launch"] == ["fork"]
    assert set(throughput.LAUNCH_DEFINITIONS) == {"command", "play_match"}


def test_a_ctrl_c_inside_the_starters_close_does_not_make_the_next_close_fail(monkeypatch):
    """The launcher closes its Starter in `finally`; a Ctrl-C that interrupted an earlier close
    must still end as a KeyboardInterrupt (exit 130), not as EBADF from closing an fd twice (exit 2)."""
    import os

    import pytest

    from arena.match import forkstart

    starter = forkstart.Starter.__new__(forkstart.Starter)
    starter._go_r, starter._go_w = fds = os.pipe()
    starter._count, starter._frozen, starter._zygote, starter._parked = 0, False, None, []
    real_close, calls = os.close, []

    def close_then_interrupt(fd: int) -> None:
        real_close(fd)
        calls.append(fd)
        if len(calls) == 1:
            raise KeyboardInterrupt  # SIGINT between the two closes

    monkeypatch.setattr(forkstart.os, "close", close_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        starter.close()
    starter.close()  # what the launcher's `finally` does: no EBADF
    monkeypatch.setattr(forkstart.os, "close", real_close)
    assert calls == [fds[0]]
    real_close(fds[1])  # the one the interrupted close left open (the launcher then exits)
