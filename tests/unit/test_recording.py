"""Recording, review and replay on whole matches in one process (memory transport).

The same Node code as `arena match --record` (the recorder included), with no
zenoh: fast enough to check every channel, both determinism directions, a
file cut at every kind of point, and the replay of every process. The real
processes are in tests/integration/test_recording.py.
"""

from __future__ import annotations

import dataclasses
import logging

import msgspec
import pytest
from mcap.reader import make_reader
from mcap.writer import Writer

from arena.config import MatchConfig
from arena.experiments import facts
from arena.match.inprocess import play_in_process
from arena.processes.recorder import data_topics
from arena.recording import scene
from arena.recording.analysis import NEEDED, analyse
from arena.recording.reader import RecordingError, load
from arena.review import replay, review
from arena.runtime.tap import Tap
from arena.schemas.keys import KEYS
from arena.schemas.messages import Cmd, TapBatch
from arena.schemas.vocabulary import SET_PIECES
from arena.strategies import registry

CFG = MatchConfig(seed=11, half_time=4.0, link="congested-wifi")


def record(tmp_path, name: str, cfg: MatchConfig = CFG):
    path = tmp_path / name
    summaries, _ = play_in_process(cfg, watch=(), record=str(path))
    return path, summaries


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    return record(tmp_path_factory.mktemp("rec"), "a.mcap")


def records_in_file_order(path) -> list[tuple[str, int, int, bytes]]:
    with open(path, "rb") as f:
        return [
            (ch.topic, m.log_time, m.sequence, m.data)
            for _, ch, m in make_reader(f, validate_crcs=True).iter_messages(log_time_order=False)
        ]


# ------------------------------------------------------------------------ taps
def test_tap_cuts_batches_on_tick_boundaries_with_a_watermark():
    sent: list[TapBatch] = []
    tap = Tap("robot/a/1", lambda raw: sent.append(msgspec.msgpack.decode(raw, type=TapBatch)), period=5)
    for k in range(12):
        tap.add("robot/a/1/cmd", k, b"\x80")
    tap.close(last_tick=11)
    assert [(b.tick, b.seq, b.final, [f.tick for f in b.frames]) for b in sent] == [
        (5, 0, False, [0, 1, 2, 3, 4]),
        (10, 1, False, [5, 6, 7, 8, 9]),
        (12, 2, True, [10, 11]),
    ]


@pytest.mark.parametrize("recording", [False, True])
def test_outbound_taps_only_when_the_match_records(recording):
    from arena.config import ProcessId
    from arena.processes.robot import RobotNode
    from arena.runtime.lockstep import Outbound
    from arena.runtime.tap import TappedOutbound
    from arena.runtime.transport import MemoryBus, MemoryTransport
    from arena.schemas.keys import Keys

    cfg = MatchConfig(tap=recording)
    node = RobotNode(ProcessId("robot", "a", 1), cfg, MemoryTransport(MemoryBus()), Keys("t"))
    assert {type(ob) for ob in node.outbound} == ({TappedOutbound} if recording else {Outbound})
    assert (node.tap is not None) == recording
    node.close()


# --------------------------------------------------------------------- content
def test_reads_back_with_crc_validation_and_every_data_key_has_a_channel(recorded):
    path, summaries = recorded
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        messages = list(reader.iter_messages())
    channels = {c.topic: c for c in summary.channels.values()}
    schemas = summary.schemas
    for topic, spec in data_topics(CFG):
        ch = channels[topic]
        assert ch.message_encoding == "msgpack"
        assert schemas[ch.schema_id].name == spec.message.__name__
        assert schemas[ch.schema_id].encoding == ""
    assert {spec.name for spec in KEYS if spec.sender != "refbox"} == {spec.name for _, spec in data_topics(CFG)}
    assert summary.statistics.message_count == len(messages)
    assert summary.statistics.chunk_count >= 8, "a chunk per second of simulated time"


def test_message_counts_are_what_every_process_sent(recorded):
    path, summaries = recorded
    sent: dict[str, int] = {}
    for s in summaries.values():
        for key, n in s.sent_by_key.items():
            sent[key] = sent.get(key, 0) + n
    rec = load(str(path))
    assert {t: n for t, n in rec.counts.items() if not t.startswith("/")} == sent
    assert summaries["recorder"].extra["messages"] == rec.counts
    assert summaries["recorder"].extra["complete"] is True


def test_log_time_is_the_simulated_time_of_the_tick(recorded):
    path, _ = recorded
    dt_ns = round(CFG.timing.dt * 1e9)
    for topic, log_time, _, data in records_in_file_order(path):
        if not topic.startswith("/"):
            assert log_time == msgspec.msgpack.decode(data)["tick"] * dt_ns, topic


def test_records_are_in_tick_then_process_order(recorded):
    path, _ = recorded
    times = [t for topic, t, _, _ in records_in_file_order(path) if not topic.startswith("/")]
    assert times == sorted(times)


def test_metadata_holds_configuration_seed_strategies_versions_and_revision(recorded):
    path, summaries = recorded
    rec = load(str(path))
    assert rec.cfg == CFG.replace(tap=True)
    arena = rec.meta["arena"]
    assert (arena["seed"], arena["home"], arena["away"]) == ("11", CFG.home, CFG.away)
    assert arena["git_revision"]
    assert rec.meta["versions"]["mcap"] and rec.meta["versions"]["soccer-arena"]
    assert set(rec.meta["schemas"]) == {spec.message.__name__ for spec in KEYS if spec.sender != "refbox"}
    assert set(rec.summaries) == set(summaries) - {"recorder"}
    assert rec.meta["recording"]["complete"] == "true" and not rec.truncated


def test_foxglove_layer_scene_at_10_hz_or_more_and_a_referee_log(recorded):
    path, _ = recorded
    with open(path, "rb") as f:
        summary = make_reader(f, validate_crcs=True).get_summary()
    channels = {c.topic: c for c in summary.channels.values()}
    for topic, schema_name in ((scene.SCENE_TOPIC, "foxglove.SceneUpdate"), (scene.LOG_TOPIC, "foxglove.Log")):
        ch = channels[topic]
        assert ch.message_encoding == "protobuf"
        assert summary.schemas[ch.schema_id].name == schema_name
        assert summary.schemas[ch.schema_id].encoding == "protobuf" and summary.schemas[ch.schema_id].data
    counts = summary.statistics.channel_message_counts
    assert counts[channels[scene.SCENE_TOPIC].id] >= 10 * 2 * CFG.half_time
    logs = b"".join(d for t, _, _, d in records_in_file_order(path) if t == scene.LOG_TOPIC)
    for text in (b"FIRST_HALF", b"KICKOFF a", b"HALF_TIME", b"END_GAME"):
        assert text in logs
    frames = [d for t, _, _, d in records_in_file_order(path) if t == scene.SCENE_TOPIC]
    for label in (b"field", b"ball", b"robot/a/0", b"robot/b/2", b"goalkeeper"):
        assert label in frames[-1]


# ----------------------------------------------------------------- determinism
def test_same_seed_same_records_other_seed_other_records(recorded, tmp_path):
    path, summaries = recorded
    again, again_summaries = record(tmp_path, "b.mcap")
    first, second = records_in_file_order(path), records_in_file_order(again)
    for i, (x, y) in enumerate(zip(first, second)):
        assert x == y, f"record {i} differs: {x[:3]} vs {y[:3]}"
    assert len(first) == len(second)
    other, _ = record(tmp_path, "c.mcap", CFG.replace(seed=12))
    assert records_in_file_order(other) != first


def test_recording_changes_nothing_in_the_match(recorded):
    _, summaries = recorded
    plain, _ = play_in_process(CFG, watch=())
    assert {n: s.digest for n, s in plain.items()} == {n: s.digest for n, s in summaries.items() if n != "recorder"}


# ---------------------------------------------------------------------- review
def test_review_reports_the_match(recorded):
    path, summaries = recorded
    r = analyse(load(str(path), keep=NEEDED))
    ref = summaries["referee"].extra
    assert r["score"] == ref["score"]
    assert [g["tick"] for g in r["goals"]] == [e["tick"] for e in ref["log"] if e["command"] == "GOAL"]
    assert sum(r["restarts"].values()) == sum(ref["events"].get(k, 0) for k in SET_PIECES)
    p = r["possession_percent"]
    assert p["a"] + p["b"] == pytest.approx(100.0, abs=0.2)
    assert r["distance_m"] == summaries["engine"].extra["distance_m"]
    assert set(r["links"]["by_class"]) == {"sensor", "wifi", "wired"}
    assert r["links"]["by_class"]["wifi"]["dropped"] > 0, "congested Wi-Fi drops"
    assert set(r["timing"]) == {str(p) for p in CFG.processes()}
    assert not r["truncated"] and r["complete"]


def test_docs_explain_every_key_of_review_json(recorded):
    from pathlib import Path

    doc = (Path(__file__).parents[2] / "docs" / "recording.md").read_text()
    table = doc.split("`--json` prints one object with these keys", 1)[1].split("\n\n", 2)[1]
    r = analyse(load(str(recorded[0]), keep=NEEDED))
    assert [k for k in [*r, "plots", "html"] if f"`{k}`" not in table] == [], "add them to docs/recording.md"


def test_review_and_arena_facts_measure_the_same_match_the_same_way(recorded):
    """One analysis: the facts from the recording equal those `arena facts` measures in process."""
    path, _ = recorded
    from_file = analyse(load(str(path), keep=NEEDED))["facts"]
    in_process = dataclasses.asdict(facts.match_facts(CFG))
    assert from_file is not None and from_file["ticks"] == CFG.total_ticks + 1
    assert from_file == in_process


def test_review_plots_write_pngs_and_an_animation(tmp_path):
    path, _ = record(tmp_path, "short.mcap", MatchConfig(seed=2, half_time=1.0))
    rec = load(str(path), keep=NEEDED)
    written = review.write_plots(rec, analyse(rec), str(tmp_path / "plots"))
    names = sorted(p.rsplit("/", 1)[-1] for p in written)
    assert names == ["heatmap.png", "match.gif", "score.png", "trajectories.png"]
    for p in written:
        with open(p, "rb") as f:
            head = f.read(8)
        assert head.startswith(b"\x89PNG") or head.startswith(b"GIF89a"), p


# ------------------------------------------------------------------ truncation
@pytest.mark.parametrize("fraction", [0.25, 0.5, 0.9, 0.999])
def test_a_cut_file_is_read_up_to_the_cut_and_said_to_be_truncated(recorded, tmp_path, fraction):
    path, _ = recorded
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * fraction)])
    rec = load(str(cut), keep=NEEDED)
    assert rec.truncated and not rec.complete and rec.problem
    r = analyse(rec)
    assert r["truncated"] and 0 < r["ticks"] <= CFG.total_ticks
    full = load(str(path))
    for topic, frames in rec.topics.items():
        assert frames == full.topics[topic][: len(frames)], "what is read is what was written"


def test_replay_of_a_truncated_file_compares_up_to_its_end(recorded, tmp_path, caplog):
    path, _ = recorded
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    result = replay.replay(str(cut), "robot/b/1")
    assert result.match and result.frames > 0 and "truncated" in result.note
    # Its senders fall silent where the file ends: the note says so, no error about peers "dead".
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR], caplog.text


def test_replay_of_a_match_stopped_by_ctrl_c_compares_up_to_where_it_stopped(recorded, caplog):
    """A whole file of an interrupted match: every process stopped at its own tick, so robot b/1's
    last `cmd` frames are missing while its inputs go on a little. It reported a divergence
    ("recorded: None") and 14 "treating ... as dead" lines."""
    import copy

    path, _ = recorded
    rec = load(str(path))
    stopped = copy.copy(rec)
    stopped.meta = {**rec.meta, "recording": {**rec.meta.get("recording", {}), "complete": "false"}}
    stopped.meta["recording"]["interrupted"] = "SIGINT"
    dt_ns = round(rec.cfg.timing.dt * 1e9)
    cut = rec.cfg.total_ticks // 2

    def upto(frames, tick):
        return [f for f in frames if f[0] <= tick * dt_ns]

    stopped.topics = {t: upto(frames, cut) for t, frames in rec.topics.items()}
    stopped.topics["robot/b/1/cmd"] = upto(rec.topics["robot/b/1/cmd"], cut - 10)
    assert not stopped.truncated and stopped.ends_early == "match stopped by SIGINT"
    result = replay.replay(stopped, "robot/b/1")
    assert result.match and result.frames > 0, result.first_difference
    assert result.note == "match stopped by SIGINT: compared up to its end" and result.digest_match is None
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR], caplog.text


@pytest.mark.parametrize(
    ("content", "needle"),
    [(b"", "is empty"), (b"hello, not mcap at all", "not an MCAP file"), (b"\x89MCAP0\r\n\x01", "cut short")],
)
def test_bad_files_are_one_line_errors(tmp_path, capsys, content, needle):
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(content)
    assert review.main(str(bad)) == 2
    assert replay.main(str(bad), ["a/1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all(needle in line for line in err), err


def test_an_mcap_file_that_is_not_a_match_recording_is_refused(tmp_path):
    other = tmp_path / "other.mcap"
    with open(other, "wb") as f:
        w = Writer(f)
        w.start()
        w.finish()
    with pytest.raises(RecordingError, match="not an arena match recording"):
        load(str(other))


# ---------------------------------------------------------------------- replay
@pytest.mark.parametrize(
    "process",
    ["engine", "referee", "basestation/a", "basestation/b"] + [f"robot/{t}/{n}" for t in "ab" for n in range(3)],
)
def test_replay_of_every_process_matches_exactly(recorded, process):
    path, _ = recorded
    result = replay.replay(str(path), process)
    assert result.match, result.first_difference
    assert result.digest_match is True
    assert result.frames > 0


def speed_up(monkeypatch, team: str, n: int, from_tick: int, factor: float = 1.2) -> None:
    """A deliberately changed robot: from `from_tick` on, robot team/n commands `factor` x its vx."""
    original = registry.get

    def tuned(name: str):
        strategy = original(name)

        def make_robot(ctx):
            brain = strategy.make_robot(ctx)
            if (ctx.team, ctx.n) == (team, n):
                step = brain.step

                def faster(tick, sense, order):
                    cmd = step(tick, sense, order)
                    return msgspec.structs.replace(cmd, vx=cmd.vx * factor) if tick >= from_tick else cmd

                brain.step = faster
            return brain

        return dataclasses.replace(strategy, make_robot=make_robot)

    monkeypatch.setattr(registry, "get", tuned)


def a_moving_tick(rec, team: str, n: int) -> int:
    """A tick after the first 2 s at which the recorded robot commanded some vx (and sent no report)."""
    cmds = rec.decoded(f"robot/{team}/{n}/cmd", Cmd)
    return next(c.tick for c in cmds if c.tick >= 101 and c.tick % rec.cfg.timing.comm_period != 0 and c.vx != 0.0)


def check_mismatch_at(rec, monkeypatch, team: str = "a", n: int = 1) -> None:
    change = a_moving_tick(rec, team, n)
    speed_up(monkeypatch, team, n, change)
    result = replay.replay(rec, f"robot/{team}/{n}")
    d = result.first_difference
    assert not result.match and result.digest_match is False
    assert (d.tick, d.key, d.fields) == (change, f"robot/{team}/{n}/cmd", ["vx"])
    assert d.replayed["vx"] == pytest.approx(1.2 * d.recorded["vx"])
    other = 0 if n else 1
    assert replay.replay(rec, f"robot/{team}/{other}").match, "the other robots are untouched"


def test_a_changed_robot_is_a_mismatch_at_the_tick_it_changed(recorded, monkeypatch):
    path, _ = recorded
    check_mismatch_at(load(str(path)), monkeypatch)


def test_replay_refuses_what_it_cannot_do(recorded, tmp_path):
    path, _ = recorded
    with pytest.raises(replay.ReplayError, match="no such process"):
        replay.replay(str(path), "robot/a/7")
    with pytest.raises(replay.ReplayError, match="bad process name"):
        replay.replay(str(path), "goalpost")
    with pytest.raises(replay.ReplayError, match="only the lockstep nodes replay"):
        replay.replay(str(path), "recorder")  # it is in the recording, so not "no such process"
    rt, _ = record(tmp_path, "rt.mcap", MatchConfig(seed=1, half_time=0.2, realtime=True))
    with pytest.raises(replay.ReplayError, match="realtime"):
        replay.replay(str(rt), "robot/a/1")


def rewrite(src, dst, change, extra=(), meta_change=lambda name, data: data) -> None:
    """Copy the recording `src` to `dst`, every record as it was but `change(topic, data)`'s messages
    and `meta_change(name, metadata)`'s metadata, and `extra` (topic, data) messages added at the end."""
    from mcap.records import Metadata
    from mcap.stream_reader import StreamReader

    with open(src, "rb") as f:
        meta = [r for r in StreamReader(f).records if isinstance(r, Metadata)]
    with open(src, "rb") as f, open(dst, "wb") as out:
        w = Writer(out)
        w.start()
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        for schema, channel, m in make_reader(f).iter_messages(log_time_order=False):
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = w.register_schema(schema.name, schema.encoding, schema.data)
            if channel.id not in channels:
                sid = schemas.get(schema.id, 0) if schema is not None else 0
                channels[channel.id] = w.register_channel(channel.topic, channel.message_encoding, sid)
            w.add_message(channels[channel.id], m.log_time, change(channel.topic, m.data), m.publish_time, m.sequence)
        for i, (topic, data) in enumerate(extra):
            w.add_message(w.register_channel(topic, "msgpack", 0), m.log_time, data, m.publish_time, i)
        for md in meta:
            w.add_metadata(md.name, meta_change(md.name, md.metadata))
        w.finish()


@pytest.mark.parametrize(("field", "value"), [("ball_x", float("nan")), ("ball_y", 1e308), ("t", float("-inf"))])
def test_a_crafted_recording_is_a_one_line_error_in_every_review_mode(recorded, tmp_path, capsys, field, value):
    """Issue 36: a world frame with x = NaN made --html and --plots exit 1 ("internal error:
    ValueError: cannot convert float NaN to integer"); bad input is exit 2 with its reason."""
    from arena.schemas.messages import World

    path, _ = recorded
    crafted = tmp_path / "crafted.mcap"
    seen = [0]

    def poison(topic: str, data: bytes) -> bytes:
        if topic != "world":
            return data
        seen[0] += 1
        if seen[0] != 30:
            return data
        world = msgspec.msgpack.decode(data, type=World)
        return msgspec.msgpack.encode(msgspec.structs.replace(world, **{field: value}))

    rewrite(path, crafted, poison)
    modes = [{}, {"as_json": True}, {"plots": str(tmp_path / "plots")}, {"html": str(tmp_path / "r.html")}]
    for mode in modes:
        assert review.main(str(crafted), **mode) == 2, mode
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "a world frame (tick 29) is not what a match sends" in err[0], (mode, err)
        assert field in err[0], err


def test_the_recorder_waits_for_a_gone_peer_from_when_its_token_vanished(tmp_path):
    """A peer that crashed mid-match gets GONE_GRACE_S from its token's vanishing, not from when every
    peer listed before it had finished: a recorded match with a crash used to end 2 s late."""
    from arena.config import ProcessId
    from arena.processes import recorder
    from arena.runtime.clock import ManualClock
    from arena.runtime.transport import MemoryBus, MemoryTransport
    from arena.schemas.keys import Keys

    clock = ManualClock(100.0)
    cfg = CFG.replace(tap=True)
    node = recorder.RecorderNode(ProcessId("recorder"), cfg, MemoryTransport(MemoryBus()), Keys("t"),
                                 path=str(tmp_path / "r.mcap"), clock=clock)  # fmt: skip
    crashed = "robot/b/1"
    assert node.peers.index(crashed) < len(node.peers) - 1, "a peer listed before others"
    node.gone.add(crashed)
    assert not node._finished()
    clock.advance(recorder.GONE_GRACE_S)  # the match plays on meanwhile; then every other peer is done
    node.finals.update(p for p in node.peers if p != crashed)
    node.summaries.update((p, object()) for p in node.peers if p != crashed)
    assert node._finished(), "its grace ran while the match played"
    node.gone.discard(crashed)  # a stopped process that resumed is waited for again, and its grace restarts
    assert not node._finished()
    node.gone.add(crashed)
    assert not node._finished()
    node.sink.finish()


def test_a_worldstate_nested_100000_deep_is_a_one_line_error_in_every_review_mode(recorded, tmp_path, capsys):
    """A worldstate whose JSON nests 100,000 deep made every review mode exit 1 (RecursionError in
    score_team); the bridge records none deeper than 32, so the file was made: exit 2, one line."""
    from arena.schemas.messages import Worldstate

    path, _ = recorded
    crafted = tmp_path / "deep.mcap"
    deep = Worldstate(tick=30, team="a", json="[" * 100_000 + "]" * 100_000)
    rewrite(path, crafted, lambda topic, data: data, [("refbox/a/worldstate", msgspec.msgpack.encode(deep))])
    modes = [{}, {"as_json": True}, {"plots": str(tmp_path / "plots")}, {"html": str(tmp_path / "r.html")}]
    for mode in modes:
        assert review.main(str(crafted), **mode) == 2, mode
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "its JSON nests 100000 levels deep, more than 32" in err[0], (mode, err)


def test_metadata_nested_100000_deep_is_skipped_not_a_crash(recorded, tmp_path, capsys):
    """A summary or the gaps metadata nested 100,000 deep raised RecursionError in msgspec."""
    path, _ = recorded
    crafted = tmp_path / "deep-meta.mcap"
    deep = "[" * 100_000 + "]" * 100_000

    def poison(name: str, data: dict) -> dict:
        if name == "summary/engine":
            return {**data, "json": '{"process": "engine", "extra": ' + deep + "}"}
        if name == "recording":
            return {**data, "gaps": deep}
        return data

    rewrite(path, crafted, lambda topic, data: data, meta_change=poison)
    rec = load(str(crafted))
    assert "engine" not in rec.summaries and "referee" in rec.summaries
    assert rec.gaps == {"?": {"error": "unreadable gaps metadata"}}
    assert review.main(str(crafted), as_json=True) == 0, capsys.readouterr().err
