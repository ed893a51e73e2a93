"""Configuration, process names, seeds, strategies and the wire contract document."""

from __future__ import annotations

import pytest

from arena.config import ConfigError, MatchConfig, ProcessId
from arena.runtime import seeds
from arena.schemas import contract
from arena.schemas.keys import KEYS, Keys
from arena.strategies import registry


def test_config_round_trips_through_json():
    cfg = MatchConfig(seed=9, home="advance-dynamic", robots=4, link="wifi", link_overrides={"wifi": {"p_gb": 0.1}})
    assert MatchConfig.from_json(cfg.to_json()) == cfg


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"robots": 0}, "--robots"),
        ({"half_time": -1}, "--half-time"),
        ({"robots": "three"}, "invalid match configuration"),
        ({"external": ["robot/a/9"]}, "no such process"),
        ({"robot": {"model": "omni5"}}, "robot.model must be omni4 or omni3"),
    ],
)
def test_bad_config_is_rejected_with_a_reason(data, message):
    with pytest.raises(ConfigError, match=message):
        MatchConfig.from_dict(data)


def test_processes_of_a_match():
    names = [str(p) for p in MatchConfig(robots=2).processes()]
    assert names == [
        "engine",
        "referee",
        "basestation/a",
        "basestation/b",
        "robot/a/0",
        "robot/a/1",
        "robot/b/0",
        "robot/b/1",
    ]


@pytest.mark.parametrize(
    ("text", "pid"),
    [
        ("a/1", ProcessId("robot", "a", 1)),
        ("robot/b/0", ProcessId("robot", "b", 0)),
        ("basestation/a", ProcessId("basestation", "a")),
        ("engine", ProcessId("engine")),
    ],
)
def test_process_names(text, pid):
    assert ProcessId.parse(text) == pid


@pytest.mark.parametrize("text", ["c/1", "robot/a", "a/x", "pitch"])
def test_bad_process_names(text):
    with pytest.raises(ConfigError, match="bad process name"):
        ProcessId.parse(text)


def test_seeds_are_derived_per_component_and_stable():
    assert seeds.derive(7, "link", "wifi") == seeds.derive(7, "link", "wifi")
    assert seeds.derive(7, "link", "wifi") != seeds.derive(8, "link", "wifi")
    assert seeds.derive(7, "link", "wifi") != seeds.derive(7, "link", "wired")
    assert seeds.derive(7, "a", "bc") != seeds.derive(7, "ab", "c")
    assert 0 <= seeds.derive(7) < 2**63


def test_strategy_names_and_aliases():
    assert registry.resolve_name("AD") == "advance-dynamic"
    assert registry.resolve_name("basic-static") == "basic-static"
    assert registry.resolve_name("bs") == "basic-static"
    with pytest.raises(ConfigError, match="unknown strategy 'tiki-taka'"):
        registry.resolve_name("tiki-taka")


def test_keys_are_prefixed_per_match():
    k = Keys("m1")
    assert k.key("cmd", "a", 1) == "arena/m1/robot/a/1/cmd"
    assert k.rel(k.key("order", "b", 2)) == "team/b/order/2"
    with pytest.raises(ValueError, match="bad match id"):
        Keys("a/b")


def test_contract_document_is_up_to_date():
    assert contract.README.read_text() == contract.render(), "run `arena schemas --write`"


def test_contract_has_one_row_per_key_and_a_section_per_message():
    text = contract.README.read_text()
    for spec in KEYS:
        assert f"`arena/<match>/{spec.pattern}`" in text
        assert f"### {spec.message.__name__}" in text


def test_link_timing_is_data_the_contract_and_the_nodes_read():
    """Schedules and lags live in KeySpec.timing; the contract renders them, the periods come from the config."""
    from pathlib import Path

    from arena.config import TimingParams
    from arena.schemas.keys import KEY_BY_NAME

    assert TimingParams().periods() == {"tick": 1, "comm": 5, "referee": 5, "world": 1}
    periods = TimingParams(comm_period=4, referee_period=10).periods()
    assert KEY_BY_NAME["order"].timing.schedule(periods) == (4, 1)
    assert KEY_BY_NAME["events"].timing.schedule(periods) == (10, 9)
    assert KEY_BY_NAME["sense"].timing.lag == 0 and KEY_BY_NAME["cmd"].timing.lag == 1
    table = contract.schedules(periods)
    assert "| `team/<team>/order/<n>` | 1, 5, 9, ... |" in table
    assert "| `engine/events` | 9, 19, 29, ... |" in table
    source = Path(contract.__file__).read_text()
    assert "0, 5, 10" not in source and "4, 9, 14" not in source, "no hand-typed timing in contract.py"


def test_our_frames_are_plain_msgpack_maps_any_msgpack_library_reads_and_writes():
    """The contract's encoding claim, checked with the reference msgpack library on a real match's frames."""
    import msgpack
    import msgspec

    from arena.match.inprocess import play_in_process
    from arena.schemas import messages as m

    _, frames = play_in_process(MatchConfig(seed=5, half_time=1.0), watch=("field", "world", "referee", "events"))
    types = {"field": m.FieldSpec, "world": m.World, "referee": m.Referee, "events": m.EngineEvents}
    for name, cls in types.items():
        assert frames[name], name
        fields = {f.name for f in msgspec.structs.fields(cls)}
        for raw in frames[name][:50]:
            plain = msgpack.unpackb(raw)  # a map with the field names as keys
            assert isinstance(plain, dict) and set(plain) <= fields, name
            ours = msgspec.msgpack.decode(raw, type=cls)
            assert plain == msgspec.to_builtins(ours), name
            assert msgspec.msgpack.decode(msgpack.packb(plain), type=cls) == ours, name  # and back
