"""Issue 19: no traceback from any command, for any input.

A table of bad invocations across every subcommand. Each must print exactly
one line on stderr, never a traceback, and exit with the documented code
(arena/cli.py: 2 for a user error). `{tmp}` is an empty directory, `{file}` a
file with garbage in it, `{busy}` a TCP port that something already listens on;
`{bin}`, `{fifo}`, `{deep}` and `{huge}` are the hostile files of `HOSTILE`.

The first case of every sub-command, and every case marked PROCESS (it opens a
zenoh session, listens, or starts a match's processes), runs as a real
`python -m arena` process: its exit code and its whole stderr as a user sees
them. The others call the same entry point, arena.cli.main, in this process
(fd-level capture, so a line written by native code counts too) with the same
assertions: ~0.1 s of interpreter startup less per case.
"""

from __future__ import annotations

import importlib.util
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from tests.integration.helpers import arena_in_process

# Without the onnx extra a policy file that is no pickle is refused for want of onnxruntime.
ONNX = importlib.util.find_spec("onnxruntime") is not None

PROCESS = "process"  # a third element: this case runs as a real process

M = ["match", "--home", "BS", "--away", "BS", "--half-time", "1"]
R = ["run", "robot", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--team", "a", "--robot", "1"]
T = ["tournament", "--strategies", "AD,BS", "--legs", "1", "--half-time", "1"]

BAD = [
    # arena match
    (["match", "--home", "BS", "--away", "BS", "--half-time", "inf"], "give a finite number"),
    (["match", "--home", "BS", "--away", "BS", "--half-time", "nan"], "give a finite number"),
    (["match", "--home", "BS", "--away", "BS", "--half-time", "1e12"], "at most 3600 s per half"),
    (["match", "--home", "BS", "--away", "BS", "--half-time", "-3"], "give a finite number"),
    (["match", "--home", "BS", "--away", "BS", "--half-time", "soon"], "is not a number of seconds"),
    ([*M, "--perception-latency", "-1"], "--perception-latency must be 0..25 ticks"),
    ([*M, "--perception-latency", "2", "--batch", "3"], "--batch must be 0 (auto) or 1..2"),
    ([*M, "--batch", "two"], "invalid int value"),
    ([*M, "--startup-timeout", "-1"], "--startup-timeout: '-1'"),
    ([*M, "--startup-timeout", "0"], "--startup-timeout: '0'"),
    ([*M, "--listen", "foo"], "--listen foo: not a zenoh endpoint"),
    ([*M, "--listen", "tcp/127.0.0.1:99999"], "a port in 0..65535"),
    ([*M, "--listen", "tcp/127.0.0.1:{busy}"], "Address already in use", PROCESS),
    ([*M, "--robots", "0"], "--robots must be between 1 and 6"),
    ([*M, "--robots", "lots"], "invalid int value"),
    (["match", "--home", "tiki-taka", "--away", "BS"], "unknown strategy 'tiki-taka'"),
    (["match", "--home", "BS"], "required: --away"),
    ([*M, "--link", "5g"], "unknown link preset '5g'"),
    ([*M, "--link-param", "wifi.warp=9"], "unknown link parameter 'warp'"),
    ([*M, "--link-param", "nonsense"], "bad link override"),
    ([*M, "--param", "a.kick_speed=99"], "kick_speed must be in 2..8, got 99.0"),
    ([*M, "--param", "a.kick_speed=nan"], "params.a.kick_speed must be finite"),
    ([*M, "--param", "a.shoot=1"], "has no parameter 'shoot'; its parameters: kick_speed (float 2..8 m/s)"),
    ([*M, "--param", "kick_speed=7"], "use TEAM.NAME=VALUE"),
    ([*M, "--external", "c/9"], "bad process name"),
    ([*M, "--external", "a/7"], "no such process"),
    ([*M, "--match", "m/x"], "bad match id"),
    ([*M, "--record", "/nonexistent/dir/m.mcap"], "does not exist"),
    ([*M, "--record", "{tmp}"], "is a directory"),
    (
        [*M, "--record", "{file}"],
        "garbage.txt exists (0.0 MB): give a new file name, or delete it first",
    ),  # was overwritten
    ([*M, "--refbox-follow", "127.0.0.1:28097"], "--refbox-follow needs --realtime"),  # was a silent 0:0
    ([*M, "--record", "/proc/m.mcap"], "cannot write it"),  # the directory exists, nobody may create files in it
    ([*M, "--seed", "-1"], "--seed must be in"),
    ([*M, "--bogus"], "arena match: error: unrecognized arguments: --bogus (see arena match --help)"),  # not arena's
    ([*M, "--half", "5"], "--half 5; did you mean --half-time? (see arena match --help)"),  # was taken as --half-time
    ([*M, "--halftime", "5"], "did you mean --half-time?"),
    ([*M, "--seeed=3"], "unrecognized arguments: --seeed=3; did you mean --seed?"),
    ([*M, "--listen", "tcp/0.0.0.0:{busy}"], "cannot listen on tcp/0.0.0.0:", PROCESS),  # was named as tls/0.0.0.0:P
    ([*M, "--credentials", "{file}"], "is not a directory"),
    # arena credentials
    (["credentials", "show", "{tmp}"], "holds no credentials: arena credentials init"),
    (["credentials", "rotate", "{tmp}"], "holds no credentials"),
    (["credentials", "init", "{file}"], "is not a directory"),
    # a folder with an unrelated .json5: init and rotate each advised running the other
    (["credentials", "init", "{stranger}"], "holds settings.json5, which is not a credentials file"),
    (["credentials", "rotate", "{stranger}"], "holds settings.json5, which is not a credentials file"),
    (["credentials", "show", "{tmp}", "robot/a/1"], "PRINCIPAL applies to rotate only"),
    (["credentials", "init", "{tmp}", "--robots", "9"], "--robots must be between 1 and 6"),
    (["credentials", "burn", "{tmp}"], "invalid choice: 'burn'"),
    (["credentials"], "required: {{init,rotate,show}}, DIR (see"),  # named PRINCIPAL, optional, and 'action'
    # arena run
    (["run", "robot", "--match", "m", "--connect", "foo", "--team", "a", "--robot", "1"], "--connect foo"),
    (["run", "robot", "--match", "m", "--connect", "tcp/127.0.0.1:1"], "needs --team"),
    (["run", "robot", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--team", "a"], "needs --robot"),
    (["run", "basestation", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--team", "a", "--robot", "1"], "--robot"),
    ([*R, "--startup-timeout", "-1"], "--startup-timeout: '-1'"),
    ([*R[:3], "m/x", *R[4:]], "bad match id"),
    ([*R, "--record", "x.mcap"], "--record does not apply"),
    ([*R, "--team", "c"], "invalid choice: 'c'"),
    ([*R, "--policy", "/nonexistent.pkl"], "policy file /nonexistent.pkl not found"),
    (["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--policy", "p.pkl"], "--policy applies to"),
    ([*R, "--credentials", "{file}"], "is not a credentials file"),
    ([*R, "--credentials", "/tmp/arena-gone/credentials/robot-a-1.json5"], "a match's temp dir is gone with its match"),
    (["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--config", "/nonexistent.json"], "cannot read"),
    (["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--config", "{file}"], "not JSON"),
    (["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--config", "/dev/zero"], "not a regular"),
    (["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--config", "{fifo}"], "not a regular"),
    (["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--config", "{deepjson}"], "nests arrays"),
    (["run", "engine", "--match", "m", "--listen", "tcp/127.0.0.1:0", "--half-time", "inf"], "finite number"),
    (["run", "router", "--match", "m", "--listen", "tcp/127.0.0.1:{busy}"], "Address already in use", PROCESS),
    (["run", "--match", "m", "--connect", "tcp/127.0.0.1:1"], "the following arguments are required: kind"),
    # arena up
    (["up", "/nonexistent/compose.yaml"], "cannot read"),
    (["up", "{file}"], "not valid YAML"),
    (["up", "/dev/zero"], "compose file /dev/zero is not a regular file"),  # was a read without end
    (["up", "{bin}"], "is not a text file"),
    (["up", "compose.yaml", "--timeout", "-5"], "--timeout: '-5'"),
    # arena tournament
    ([*T, "--leg", "2"], "arena tournament: error: unrecognized arguments: --leg 2; did you mean --legs?"),
    ([*T, "--job", "2"], "did you mean --jobs? (see arena tournament --help)"),  # was taken as --jobs
    ([*T, "--out", "{file}"], "exists and is not a directory"),
    (
        [*T, "--out", "{tmp}/typo", "--resume"],
        "{tmp}/typo does not exist, so there is nothing to resume",
    ),  # was 0 of N kept
    ([*T, "--out", "{tmp}", "--resume"], "holds no tournament, so there is nothing to resume"),
    (["tournament", "--strategies", "AD"], "at least two different strategies"),
    (["tournament", "--strategies", "AD,nope"], "unknown strategy 'nope'"),
    ([*T, "--legs", "0"], "--legs: '0'"),
    (["tournament", "--half-time", "inf"], "finite number"),
    ([*T, "--param", "AS.kick_speed=7"], "advance-static plays no match of this tournament"),
    ([*T, "--param", "AD.kick_speed=0.5"], "kick_speed must be in 2..8, got 0.5"),
    ([*T, "--param", "AD.dribble=1"], "advance-dynamic has no parameter 'dribble'"),
    ([*T, "--link-param", "x"], "bad link override"),
    ([*T, "--jobs", "-1"], "--jobs"),
    ([*T, "--robots", "9"], "--robots"),
    # arena experiment
    (["experiment", "run", "{file}"], "is not valid TOML", PROCESS),
    (["experiment", "run", "{tmp}"], "is not a regular file"),
    (["experiment", "run", "/nonexistent/exp.toml"], "cannot read experiment file"),
    (["experiment", "run", "{file}", "--jobs", "-1"], "--jobs must be 0"),
    (["experiment", "run", "{file}", "--ray", "nohost"], "give auto or HOST:PORT"),
    (["experiment", "compare", "--candidate", "AD"], "required: --baseline"),
    (["experiment", "compare", "--candidate", "AD", "--baseline", "tiki-taka"], "unknown strategy 'tiki-taka'"),
    (["experiment", "compare", "--candidate", "AD", "--baseline", "BS", "--elo0", "5", "--elo1", "1"], "elo0 < elo1"),
    (["experiment", "compare", "--candidate", "AD", "--baseline", "BS", "--alpha", "0"], "alpha and beta"),
    (["experiment", "compare", "--candidate", "AD", "--baseline", "BS", "--max-pairs", "0"], "--max-pairs must be"),
    (["experiment", "compare", "--candidate", "AD", "--baseline", "BS", "--half-time", "nan"], "--half-time"),
    (["experiment", "compare", "--candidate", "AD", "--baseline", "AD", "--opponents", "BS"], "name two"),
    (["experiment"], "the following arguments are required"),
    # arena bench
    (["bench", "match", "--runs", "0"], "--runs: '0'"),
    (["bench", "match", "--half-time", "1e12"], "at most 3600 s"),
    (["bench", "match", "--half-time", "0.001"], "shorter than one tick"),  # before "run 1/3" is printed
    (["bench", "record", "--link", "moon"], "unknown link preset 'moon'"),  # was two empty matches, then no MCAP
    (["bench", "throughput", "--strategy", "nope"], "unknown strategy 'nope'"),  # was an internal error
    (["bench", "throughput", "--rsoccer", "/nonexistent/python"], "--rsoccer /nonexistent/python: no such interpreter"),
    (["bench", "match", "--rsoccer", "/usr/bin/python3"], "--rsoccer does not apply to arena bench match"),
    (["bench", "nav", "--trials", "0"], "--trials: '0'"),
    (["bench", "nav", "--scenarios", "/nonexistent.toml"], "nonexistent.toml"),
    (["bench", "nav", "--only", "nosuch"], "nosuch"),
    (["bench", "frob"], "invalid choice: 'frob'"),
    (["bench", "learn", "--link", "moon"], "--link does not apply to arena bench learn (it takes --strategy"),  # exit 0
    (["bench", "scenario", "--robots", "2"], "--robots does not apply to arena bench scenario (it takes --runs and"),
    (["bench", "nav", "--runs", "2"], "--runs does not apply to arena bench nav"),
    # arena facts
    (["facts", "--worker", "2"], "did you mean --workers? (see arena facts --help)"),
    (["facts", "--half-time", "inf"], "finite number"),
    (["facts", "--seeds", "0"], "must be at least 1"),
    (["facts", "--round-robin", "AD"], "needs at least two different strategies"),
    (["facts", "--home", "nope"], "unknown strategy 'nope'"),
    (["facts", "--perception-latency", "99"], "--perception-latency must be 0..25 ticks, got 99"),
    # arena operator
    (["operator", "--match", "m", "--connect", "tcp/127.0.0.1:1", "not json"], "ACTION 1: JSON is malformed"),
    (["operator", "--match", "m", "--connect", "tcp/127.0.0.1:1", '{{"x": 1}}'], "missing required field `type`"),
    # arena scenario
    (["scenario", "run", "--seeds", "0"], "--seeds: expected a whole number 1..100000"),
    (["scenario", "run", "x", "--seed", "1", "--seeds", "2"], "--seeds: not allowed with argument --seed"),
    (["scenario", "library", "x"], "library takes no FILE|DIR, got 'x'"),  # was ignored
    (  # an existing recording is never overwritten, as with arena match --record
        ["scenario", "run", "{lib}/rules/09-goal.scenario.toml", "--seed", "0", "--record", "{file}"],
        "exists (0.0 MB): give a new file name",
    ),
    (  # said before the runs, not after them
        ["scenario", "run", "{lib}/rules/09-goal.scenario.toml", "--junit", "/nonexistent/dir/r.xml"],
        "--junit /nonexistent/dir/r.xml: its directory does not exist",
    ),
    (["scenario"], "required: {{run,library}} (see"),
    (
        ["scenario", "run", "--jbos", "2"],
        "arena scenario: error: unrecognized arguments: --jbos 2; did you mean --jobs?",
    ),
    # arena review
    (
        ["review", "m.mcap", "--plot", "d"],
        "arena review: error: unrecognized arguments: --plot d; did you mean --plots?",
    ),
    (["review", "/nonexistent.mcap"], "cannot read"),
    (["review", "{file}"], "not an MCAP file"),
    (["review", "{file}", "--plots", "{file}"], "exists and is not a directory"),
    # arena replay
    (["replay", "/nonexistent.mcap", "--process", "a/1"], "cannot read"),
    (["replay", "{file}", "--process", "a/1"], "not an MCAP file"),
    (["replay", "/nonexistent.mcap"], "required: --process"),
    # arena config
    (["config"], "one of the arguments --print --check is required"),
    (["config", "--check", "/nonexistent.toml"], "cannot read"),
    (["config", "--check", "{file}"], "not valid TOML"),
    (["match", "--config", "{file}"], "not valid TOML"),
    (["match", "--config", "{bin}"], "is not a text file (byte 0 is not UTF-8"),  # was internal error, exit 1
    (["match", "--config", "{fifo}"], "is not a regular file"),  # was a hang
    (["match", "--config", "/dev/zero"], "is not a regular file"),  # was a read without end
    (["match", "--config", "{tmp}"], "is a directory: give a file"),
    (["match", "--config", "{deep}"], "nests arrays or tables too deep"),  # was RecursionError
    (["config", "--check", "{huge}"], "robot.mass must be at most 1000 kg, got 1e+308"),  # was accepted
    (
        ["match", "--home", "policy:{file}", "--away", "BS"],
        "is not a valid ONNX model" if ONNX else "needs onnxruntime",
    ),
    (["match", "--home", "policy:/nonexistent.pkl", "--away", "BS"], "policy file /nonexistent.pkl not found"),
    (["match", "--home", "policy:", "--away", "BS"], "'policy:' names no file: policy:PATH"),  # was the cwd, read
    (["match", "--home", "policy:{tmp}", "--away", "BS"], "is a directory: give the file save_policy wrote"),
    # arena operator
    (  # the valid types were not listed
        ["operator", "--match", "m", "--connect", "tcp/127.0.0.1:1", '{{"type": "teleport_bal"}}'],
        "ACTION 1: Invalid value 'teleport_bal' - at `$.type` (the types: teleport_ball, teleport_robot, referee)",
    ),
    (["operator", "--match", "m", '{{"type": "teleport_ball"}}'], "required: --connect"),
    (
        [
            "operator",
            "--match",
            "m",
            "--connect",
            "tcp/127.0.0.1:1",
            "--credentials",
            "/nonexistent.json5",
            '{{"type": "referee", "command": "STOP"}}',
        ],
        "cannot read --credentials /nonexistent.json5",
    ),
    (
        ["operator", "--match", "m", "--connect", "tcp/127.0.0.1:1", '{{"type": "teleport_ball"}}'],
        "cannot connect to",
        PROCESS,
    ),
    # arena experiment
    (
        ["experiment", "tune", "--strategy", "AD", "--opponents", "BS", "--params", "kick"],
        "parameters are kick_speed",
    ),
    (["experiment", "tune", "--strategy", "chase", "--opponents", "BS"], "chase declares no parameters to tune"),
    (["experiment", "tune", "--strategy", "AD", "--opponents", "BS", "--a", "-1"], "--a must be > 0"),
    (
        ["experiment", "tune", "--strategy", "AD", "--opponents", "BS", "--out", "{tmp}/t", "--resume"],
        "holds no tune.json",
    ),
    (["experiment", "tune", "--strategy", "AD"], "required: --opponents"),
    # arena strategies
    (["strategies", "tiki-taka"], "once its package is installed: entry point soccer_arena.strategies"),
    (["strategies", "--check"], "unrecognized arguments: --check"),
    # arena schemas, and the top level
    (["schemas", "--check", "--write"], "not allowed with argument"),
    (["frobnicate"], "invalid choice"),
    ([], "required: <command>"),
]


@pytest.fixture(scope="module")
def busy_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        yield s.getsockname()[1]


@pytest.fixture(scope="module")
def garbage(tmp_path_factory):
    path = tmp_path_factory.mktemp("bad") / "garbage.txt"
    path.write_text("this is neither JSON, YAML, nor MCAP: {[\n")
    return path


HOSTILE = {
    "bin": b"\x89MCAP0\r\n\xff\x00" * 64,  # a recording named by mistake
    "deep": b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n",
    "huge": b"[robot]\nmass = 1e308\n",
    "deepjson": b"[" * 100_000,
}


@pytest.fixture(scope="module")
def hostile(tmp_path_factory) -> dict[str, str]:
    import os

    d = tmp_path_factory.mktemp("hostile")
    for name, data in HOSTILE.items():
        (d / f"{name}.toml").write_bytes(data)
    os.mkfifo(d / "fifo.toml")
    (d / "stranger").mkdir()
    (d / "stranger" / "settings.json5").write_text('{"theme": "dark"}\n')
    return {name: str(d / f"{name}.toml") for name in (*HOSTILE, "fifo")} | {"stranger": str(d / "stranger")}


def _cases() -> list[tuple[list[str], str, bool]]:
    """BAD as (args, needle, in a process): the first case of each sub-command, and the PROCESS ones."""
    seen: set[str] = set()
    cases = []
    for args, needle, *process in BAD:
        first = (args[:1] or [""])[0] not in seen
        seen.add((args[:1] or [""])[0])
        cases.append((args, needle, first or process == [PROCESS]))
    return cases


CASES = _cases()


@pytest.mark.parametrize(
    ("args", "needle", "process"),
    CASES,
    ids=[("process: " if process else "") + " ".join(a)[:60] for a, _, process in CASES],
)
def test_a_bad_invocation_is_one_line_and_exit_2(args, needle, process, busy_port, garbage, hostile, tmp_path, capfd):
    from arena.scenarios.library import LIBRARY

    argv = [a.format(busy=busy_port, file=garbage, tmp=tmp_path, lib=LIBRARY, **hostile) for a in args]
    if process:
        r = subprocess.run([sys.executable, "-m", "arena", *argv], capture_output=True, text=True, timeout=60)
    else:
        r = arena_in_process(argv, capfd)
    assert "Traceback" not in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert needle.format(busy=busy_port, file=garbage, tmp=tmp_path) in r.stderr, r.stderr
    assert r.returncode == 2, r.stderr


def test_the_table_covers_every_subcommand():
    from arena.cli import parser

    sub = next(a for a in parser()._actions if a.dest == "command")
    covered = {args[0] for args, *_ in BAD if args}
    assert set(sub.choices) - covered == set(), "every subcommand needs bad invocations in the table"
    assert len(BAD) >= 40
    in_a_process = {args[0] for args, _, process in CASES if args and process}
    assert in_a_process == covered, "every subcommand needs a case run as a real process"


def test_an_internal_failure_is_one_line_naming_the_log(tmp_path, monkeypatch, capsys):
    from arena import cli
    from arena.commands import schemas

    def broken(args):
        raise ZeroDivisionError("the bug")

    monkeypatch.setattr(schemas, "run", broken)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    assert cli.main(["schemas", "--check"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "internal error: ZeroDivisionError: the bug" in err
    log = Path(err.rsplit("details in ", 1)[1].rstrip(")"))
    assert log.parent == tmp_path and "Traceback" in log.read_text() and "the bug" in log.read_text()


@pytest.mark.parametrize(
    ("command", "said"),
    [
        ("review", "arena review: interrupted"),
        ("match", "arena match: interrupted; every process of the match was stopped"),
        ("facts", "arena facts: interrupted; every match still playing was stopped, its worker with it"),  # "the match"
    ],
)
def test_ctrl_c_is_one_line_and_exit_130(monkeypatch, capsys, command, said):
    from arena import cli

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli.command(command), "run", interrupted)
    argv = {"review": ["review", "m.mcap"], "facts": ["facts", "--seeds", "2"]}.get(command, M)
    assert cli.main(argv) == 130
    assert capsys.readouterr().err.strip() == said


def test_version():
    r = subprocess.run([sys.executable, "-m", "arena", "--version"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and r.stdout.startswith("arena ") and r.stdout.split()[1][0].isdigit()


@pytest.mark.parametrize(
    ("env", "args", "needle"),
    [
        ({"ZENOH_RUNTIME": "garbage"}, M, "ZENOH_RUNTIME='garbage' is not a zenoh runtime setting"),
        ({"ARENA_MATCH": "bad/id"}, ["up", "compose.yaml"], "ARENA_MATCH: bad match id 'bad/id'"),
        ({"ARENA_HALF_TIME": "1e12"}, ["up", "compose.yaml"], "service engine refused to start: --half-time must be"),
    ],
)
def test_a_bad_environment_variable_is_one_line_and_exit_2(env, args, needle):
    import os

    r = subprocess.run(
        [sys.executable, "-m", "arena", *args],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, **env},
        cwd=Path(__file__).resolve().parents[2],
    )
    assert "Traceback" not in r.stderr and "panicked" not in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and needle in r.stderr, r.stderr
    assert r.returncode == 2


def test_no_parser_takes_an_abbreviated_flag():
    from arena.cli import parser

    top = parser()
    sub = next(a for a in top._actions if a.dest == "command")
    assert not top.allow_abbrev
    assert [name for name, p in sub.choices.items() if p.allow_abbrev] == []


def test_a_jobs_of_0_is_said_to_mean_the_default(capfd):
    """`--jobs 0` silently meant "one per core", which no help text said."""
    for cmd, flag, means in (("tournament", "--jobs", "one per core"), ("facts", "--workers", "up to 2")):
        r = arena_in_process([cmd, "--help"], capfd)
        assert r.returncode == 0 and f"0 (the default): {means}" in " ".join(r.stdout.split()), (cmd, flag)


def test_a_malformed_listen_is_said_before_a_process_is_forked(monkeypatch):
    """`arena match --listen foo` forked the match's ten processes, then refused the endpoint."""
    from arena.config import MatchConfig
    from arena.match import forkstart, launcher
    from arena.runtime.session import EndpointError

    monkeypatch.setattr(forkstart, "starter", lambda *args: pytest.fail("forked before the endpoint was checked"))
    with pytest.raises(EndpointError, match="--listen foo: not a zenoh endpoint"):
        launcher.play_match(MatchConfig(), listen="foo")
