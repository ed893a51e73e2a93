"""The MSL RefBox protocol library: encodings, framing, worldstate validation, team table."""

from __future__ import annotations

import json

import pytest

from arena.rules import refbox_protocol as rp

GOOD = {"type": "worldstate", "teamName": "T", "intention": "", "ageMs": 12, "robots": [], "balls": [], "obstacles": []}


def test_json_command_is_one_object_and_a_nul():
    assert rp.encode_json("KICKOFF", "224.16.32.80") == b'{"command":"KICKOFF","targetTeam":"224.16.32.80"}\0'
    assert rp.encode_json("START") == b'{"command":"START","targetTeam":""}\0'
    assert json.loads(rp.encode_json("IS_ALIVE", "x", 3)[:-1]) == {
        "command": "IS_ALIVE",
        "targetTeam": "x",
        "robotID": 3,
    }
    assert b"robotID" not in rp.encode_json("KICKOFF", "x", 3)  # only the robot commands carry it


@pytest.mark.parametrize(
    ("command", "colour", "char"),
    [
        ("KICKOFF", "cyan", b"K"),
        ("KICKOFF", "magenta", b"k"),
        ("START", "", b"s"),
        ("STOP", "", b"S"),
        ("FIRST_HALF", "", b"1"),
        ("SECOND_HALF", "", b"2"),
        ("HALF_TIME", "", b"h"),
        ("END_GAME", "", b"e"),
        ("DROP_BALL", "", b"N"),
        ("GOAL", "magenta", b"a"),
        ("CORNER", "cyan", b"C"),
        ("WELCOME", "", b"W"),
        ("RESET", "", b"Z"),
        ("PARK", "", b"L"),
    ],
)
def test_legacy_characters(command, colour, char):
    assert rp.encode_legacy(command, colour) == char
    assert rp.CommandReader().feed(char) == [rp.Command(command, colour=colour)]


def test_legacy_has_no_character_for_some_commands():
    assert rp.encode_legacy("IS_ALIVE", "cyan") is None
    assert rp.encode_legacy("KICKOFF", "") is None  # a team command needs its colour


def test_the_30_commands_and_their_sides():
    assert len(rp.COMMANDS) == len(set(rp.COMMANDS)) == 30
    assert rp.TEAM_COMMANDS < set(rp.COMMANDS)
    assert [rp.colour_of(t) for t in "ab"] == ["cyan", "magenta"]
    assert [rp.colour_of(t, swap=True) for t in "ab"] == ["magenta", "cyan"]
    assert all(rp.team_of(rp.colour_of(t, s), s) == t for t in "ab" for s in (False, True))


@pytest.mark.parametrize("chunk", [1, 7, 10_000])
def test_command_reader_any_segmentation(chunk):
    stream = rp.encode_json("WELCOME", "t") + b"K" + rp.encode_json("STOP") + b"s"
    reader, got = rp.CommandReader(), []
    for i in range(0, len(stream), chunk):
        got += reader.feed(stream[i : i + chunk])
    assert [c.name for c in got] == ["WELCOME", "KICKOFF", "STOP", "START"]
    assert got[0].target == "t" and got[1].colour == "cyan"
    assert not reader.errors


def test_command_reader_reports_garbage():
    reader = rp.CommandReader()
    assert reader.feed(b'{"command":"NOPE"}\0{bad\0?') == []
    assert len(reader.errors) == 3


def test_command_reader_bounds_its_errors_and_survives_deep_json():
    """A RefBox (or anything on its port) is input too: 1 MB of unknown characters is one pass and
    20 logged errors, the rest counted; a command nested 90,000 deep is an error, not a
    RecursionError that ends the reading thread; an overlong command is dropped up to its NUL."""
    reader = rp.CommandReader()
    assert reader.feed(b"?" * 1_000_000) == []
    assert len(reader.errors) == rp.LOG_FIRST_ERRORS and reader.dropped == 1_000_000 - rp.LOG_FIRST_ERRORS
    reader = rp.CommandReader()
    assert reader.feed(b'{"command":' + b"[" * 90_000 + b"\0" + rp.encode_json("STOP")) == [rp.Command("STOP")]
    assert reader.errors == [f"JSON command nested deeper than {rp.MAX_DEPTH} levels"]
    reader, got = rp.CommandReader(), []
    for i in range(0, 300_000, 1000):  # 300 kB of one command without its NUL, then the NUL and a good one
        got += reader.feed(b"{" + b" " * 999 if i == 0 else b" " * 1000)
    got += reader.feed(b"\0s")
    assert [c.name for c in got] == ["START"]
    assert reader.errors == [f"command not terminated within {rp.MAX_UNTERMINATED} bytes"]


def reference_nesting(raw: str) -> int:
    """A character-by-character JSON string scanner: the oracle for `rp.nesting`."""
    depth = deepest = 0
    in_string = escaped = False
    for c in raw:
        if in_string:
            if escaped:
                escaped = False
            elif c == "\\":
                escaped = True
            elif c == '"':
                in_string = False
        elif c == '"':
            in_string = True
        elif c in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif c in "]}":
            depth -= 1
    return deepest


# Inputs that made a backtracking pattern for JSON strings quadratic, and other hostile shapes,
# at the RefBox's size limit and at ten times it. Each is parsed in a few ms (`arena bench refbox`
# prints the cost per kB at both sizes); before, the first took over a minute with the GIL held.
PATHOLOGICAL = [
    ('"' + '\\"' * 49_990, 0),  # the message: an unterminated string of escaped quotes
    ('"' + '\\"' * 499_990, 0),
    ('"[' * 50_000, 25_000),  # every other bracket is outside a string
    ("\\" * 1_000_000, 0),
    ("[" * 1_000_000, 1_000_000),
    ('["' + "\\\\" * 100_000 + '", [[1]]]', 3),  # escaped backslashes end before the closing quote
    ('{"a": "' + "\u00e9[" * 100_000 + '"}', 1),
]


@pytest.mark.parametrize(("raw", "depth"), PATHOLOGICAL, ids=lambda x: f"{len(x)}" if isinstance(x, str) else None)
def test_nesting_of_pathological_messages(raw, depth):
    assert rp.nesting(raw) == depth
    r = rp.validate_worldstate(raw)
    assert r.doc is None and (r.reason == "too-deep") == (depth > rp.MAX_DEPTH)


def test_the_100_kB_message_through_the_reader():
    message = b'"' + b'\\"' * 49_990 + b"\0"
    (r,) = rp.WorldstateReader().feed(message)
    assert r.reason == "malformed-json" and len(message) > 100_000 - 30


def test_nesting_agrees_with_a_character_scanner():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    # JSON's tokens, strings with escapes among them and perhaps unterminated at the end; outside
    # strings a backslash is no JSON, the parser stops there, and the counts may differ after it.
    string = st.lists(st.sampled_from(["a", "[", "{", "]", "\\\\", '\\"', "\u00e9", "\\n"]), max_size=8).map(
        lambda parts: '"' + "".join(parts) + '"'
    )
    token = st.one_of(st.sampled_from(["[", "]", "{", "}", ",", ":", "1", " "]), string)
    text = st.tuples(st.lists(token, max_size=30), st.booleans()).map(
        lambda t: "".join(t[0])[: -1 if t[1] and t[0] and t[0][-1].endswith('"') else None]
    )

    @settings(max_examples=400, deadline=None, database=None)
    @given(text)
    def agree(raw: str) -> None:
        assert rp.nesting(raw) == max(0, reference_nesting(raw))

    agree()


def enc(doc) -> bytes:
    return json.dumps(doc).encode() + b"\0"


@pytest.mark.parametrize(
    ("payload", "reason"),
    [
        (b"{not json\0", "malformed-json"),
        (b"[1,2]\0", "malformed-json"),
        (b"\0", "malformed-json"),
        (enc({k: v for k, v in GOOD.items() if k != "type"}), "missing-key"),
        (enc(GOOD | {"type": "hello"}), "wrong-type"),
        (enc({k: v for k, v in GOOD.items() if k != "ageMs"}), "missing-key"),
        (enc(GOOD | {"ageMs": "12"}), "missing-key"),
        (enc({k: v for k, v in GOOD.items() if k != "teamName"}), "missing-key"),
        (enc(GOOD | {"robots": {}}), "missing-key"),
        (enc({k: v for k, v in GOOD.items() if k != "obstacles"}), "missing-key"),
    ],
)
def test_worldstate_errors_as_the_refbox(payload, reason):
    (r,) = rp.WorldstateReader().feed(payload)
    assert r.doc is None and r.reason == reason


def test_worldstates_split_and_joined_anyhow():
    stream = enc(GOOD) * 3
    for chunk in (1, 13, len(stream)):
        reader, got = rp.WorldstateReader(), []
        for i in range(0, len(stream), chunk):
            got += reader.feed(stream[i : i + chunk])
        assert [r.doc["ageMs"] for r in got] == [12, 12, 12]


def test_unterminated_message_is_dropped_once_and_the_stream_recovers():
    reader = rp.WorldstateReader(limit=200)
    out = reader.feed(b"x" * 120) + reader.feed(b"x" * 120)
    assert [r.reason for r in out] == ["not-terminated"]
    out = reader.feed(b"x" * 500 + b"\0" + enc(GOOD))
    assert [(r.reason, r.doc is not None) for r in out] == [("", True)]
    out = reader.feed(b"y" * 199 + b"\0" + b"z" * 201 + b"\0")  # a NUL past the limit is too late
    assert [r.reason for r in out] == ["malformed-json", "not-terminated"]


def test_team_table_and_identification():
    table = rp.parse_team_table(
        json.dumps(
            [
                {"UnicastAddr": "172.16.80.*", "Team": "IRIS", "MulticastAddr": "224.16.32.80", "side": "a"},
                {"UnicastAddr": "127.0.0.*", "Team": "local", "protocol": "legacy"},
            ]
        )
    )
    assert rp.identify("172.16.80.17", table).name == "IRIS"
    assert rp.identify("::1", table).protocol == "legacy"
    assert rp.identify("::ffff:127.0.0.5", table).name == "local"
    assert rp.identify("10.0.0.1", table) is None
    for bad in ('{"a": 1}', "[{}]", '[{"UnicastAddr": "1.2.3.4"}]', '[{"UnicastAddr": "1.2.3.*", "side": "c"}]'):
        with pytest.raises(rp.ProtocolError):
            rp.parse_team_table(bad)


def test_endpoints():
    assert rp.parse_endpoint("tcp/0.0.0.0:28097") == ("0.0.0.0", 28097)
    assert rp.parse_endpoint("10.0.0.2:1234") == ("10.0.0.2", 1234)
    assert rp.parse_endpoint("tcp/[::1]:5") == ("::1", 5)
    assert rp.parse_endpoint("refbox.local") == ("refbox.local", rp.PORT)
    for bad in ("udp/1.2.3.4:5", "tcp/:5", "h:xx", "h:70000"):
        with pytest.raises(rp.ProtocolError):
            rp.parse_endpoint(bad)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--refbox", "tcp/127.0.0.1:xx"], "is not a number"),
        (["--refbox", "udp/1.2.3.4:5"], "only tcp/HOST:PORT"),
        (["--refbox-teams", "/no/such/file.json"], "cannot read --refbox-teams"),
        (["--refbox-protocol", "c=json"], "use a=json"),
        (["--refbox-targets", "same,same"], "two different strings"),
        (["--refbox-wait", "1"], "--refbox-wait needs --refbox"),
        (["--refbox", "tcp/127.0.0.1:0", "--via-refbox"], "--via-refbox needs --realtime"),  # 28097 may be busy
        (["--via-refbox", "--realtime"], "--via-refbox needs the bridge"),
        (["--refbox-follow", "host:port"], "is not a number"),
        (["--refbox", "tcp/127.0.0.1:0", "--via-refbox", "--realtime"], "needs a fixed --refbox port"),
    ],
)
def test_bad_refbox_flags_are_one_line_and_exit_2(flags, message, capsys):
    from arena import cli

    assert cli.main(["match", "--home", "BS", "--away", "BS", *flags]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_busy_port_is_refused_before_the_match(capsys):
    import socket

    from arena import cli

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert cli.main(["match", "--home", "BS", "--away", "BS", "--refbox", f"tcp/127.0.0.1:{port}"]) == 2
    assert "cannot listen there" in capsys.readouterr().err
