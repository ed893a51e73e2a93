"""Whole matches in one process over the memory transport: determinism, step by step."""

from __future__ import annotations

import msgspec
import pytest

from arena.config import MatchConfig
from arena.match.inprocess import play_in_process
from arena.schemas.messages import World

decode_world = msgspec.msgpack.Decoder(World).decode


def first_difference(a: list[bytes], b: list[bytes]) -> str | None:
    for wa, wb in zip(a, b):
        if wa != wb:
            x, y = decode_world(wa), decode_world(wb)
            return f"tick {x.tick}: ball ({x.ball_x:.4f}, {x.ball_y:.4f}) vs ({y.ball_x:.4f}, {y.ball_y:.4f})"
    if len(a) != len(b):
        return f"lengths differ: {len(a)} vs {len(b)} world frames"
    return None


@pytest.fixture(scope="module")
def seed5():
    return play_in_process(MatchConfig(seed=5, half_time=3.0, link="congested-wifi"))


def test_same_seed_same_world_at_every_tick(seed5):
    _, frames = seed5
    _, again = play_in_process(MatchConfig(seed=5, half_time=3.0, link="congested-wifi"))
    diff = first_difference(frames["world"], again["world"])
    assert diff is None, f"first difference at {diff}"


def test_other_seed_other_match(seed5):
    _, frames = seed5
    _, other = play_in_process(MatchConfig(seed=6, half_time=3.0, link="congested-wifi"))
    assert first_difference(frames["world"], other["world"]) is not None


def test_every_tick_has_a_world_frame_and_the_match_flow_is_complete(seed5):
    summaries, frames = seed5
    ticks = [decode_world(w).tick for w in frames["world"]]
    assert ticks == list(range(301))
    events = summaries["referee"].extra["events"]
    for name in ("FIRST_HALF", "KICKOFF", "HALF_TIME", "SECOND_HALF", "END_GAME"):
        assert events.get(name, 0) >= 1, events
    assert [e["command"] for e in summaries["referee"].extra["log"][-3:]] == ["END_GAME", "PARK", "GAMEOVER"]


def test_links_really_drop_under_congested_wifi(seed5):
    summaries, _ = seed5
    wifi = [s.links["wifi"] for s in summaries.values() if "wifi" in s.links]
    assert sum(w["dropped"] for w in wifi) > 0
    assert all(s.rejected == 0 and not s.dead for s in summaries.values())


def _noisy_referee():
    """A referee that sends a bad frame for every tick just before its real one."""
    from arena.processes.referee import RefereeNode
    from arena.schemas.messages import RefCommand, Referee

    bad = [
        dict(command="CELEBRATE"),  # not an MSL RefBox command: does not decode (RefCommandName)
        dict(command="START", commands=[RefCommand(name="KICKOFF")]),  # a kickoff for nobody: invalid
        dict(command="START", command_team="c"),  # no such team: does not decode
        dict(command="START", commands=[RefCommand(name="GOAL", team="c")]),  # likewise
    ]

    class NoisyReferee(RefereeNode):
        def act(self, k: int) -> None:
            self.ref_out.send(Referee(tick=k, stage="FIRST_HALF", **bad[(k // 5) % len(bad)]))
            super().act(k)

    return NoisyReferee


def test_bad_referee_frames_are_rejected_by_engine_and_base_stations_and_change_nothing(monkeypatch):
    from arena.match import inprocess
    from arena.processes import node_class

    cfg = MatchConfig(seed=3, half_time=2.0)
    clean, _ = play_in_process(cfg, watch=())
    noisy = _noisy_referee()
    monkeypatch.setattr(inprocess, "node_class", lambda kind: noisy if kind == "referee" else node_class(kind))
    summaries, _ = play_in_process(cfg, watch=())
    used = cfg.total_ticks // cfg.timing.referee_period  # frames sent before the last tick: 40, half of each kind
    for name in ("engine", "basestation/a", "basestation/b"):
        reasons = summaries[name].rejected_reasons
        # The kickoff for nobody decodes: it advances the link with a safe default, and the real frame
        # for the same tick then counts as a conflict (and takes its place).
        assert reasons == {"invalid": used // 4, "malformed": 3 * used // 4, "conflict": used // 4}, (name, reasons)
        assert summaries[name].digest == clean[name].digest, f"{name} acted on a rejected frame"
    assert summaries["referee"].extra["events"] == clean["referee"].extra["events"]
    assert [e["command"] for e in summaries["referee"].extra["log"][-3:]] == ["END_GAME", "PARK", "GAMEOVER"]


def test_ctrl_c_in_process_leaves_a_whole_recording_that_says_it_was_stopped(tmp_path, monkeypatch):
    """The in-process engine left a truncated file on Ctrl-C; the recorder process writes one that says SIGINT."""
    from arena.match import inprocess
    from arena.recording.reader import load
    from arena.runtime import coop

    def interrupted(bus, tasks, **kw):
        kw["on_idle"]()
        raise KeyboardInterrupt

    monkeypatch.setattr(coop, "drive", interrupted)
    path = tmp_path / "stopped.mcap"
    with pytest.raises(KeyboardInterrupt):
        inprocess._play(MatchConfig(half_time=1.0, home="BS", away="BS"), (), record=str(path))
    rec = load(str(path))
    assert not rec.truncated and rec.meta["recording"]["interrupted"] == "SIGINT"


def test_a_match_collects_its_own_cycles_and_leaves_nothing_frozen(monkeypatch):
    """The caller's heap is frozen without a full collection before the match (runtime/node.py
    `match_heap`); the cycles the match leaves are collected as it returns, and nothing stays frozen."""
    import gc

    full = []
    collect = gc.collect
    collect()  # the caller's garbage so far: frozen with the caller's heap, not the match's to collect
    monkeypatch.setattr(gc, "collect", lambda generation=2: full.append(generation) or collect(generation))
    play_in_process(MatchConfig(seed=1, half_time=0.5), watch=())
    assert full == [1, 2], "one young collection before, one full collection (of the match's objects) after"
    assert gc.get_freeze_count() == 0
    assert collect() == 0, "the match's cycles were collected as it returned"


def test_a_processs_last_match_leaves_its_cycles_to_the_exit(monkeypatch):
    """`arena match` ends its process with the match (`InProcess(last=True)`): no full collection
    after it, which would only free what the exit drops anyway; nothing stays frozen either."""
    import gc

    from arena.match import InProcess, play

    full = []
    collect = gc.collect
    collect()
    monkeypatch.setattr(gc, "collect", lambda generation=2: full.append(generation) or collect(generation))
    play(MatchConfig(seed=1, half_time=0.5), engine=InProcess(last=True))
    assert full == [1], "only the young collection before the match"
    assert gc.get_freeze_count() == 0
