"""Bad input on the command line: one line, exit code 2, never a traceback.

The last case runs as a real `arena` process; the others, and the help texts, through the same
entry point in this process (tests/unit/test_bad_invocations.py has a real process per sub-command).
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.integration.helpers import arena_in_process


def arena(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arena", *args], capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["match", "--home", "BS", "--away", "BS", "--robots", "lots"], "invalid int value"),
        (["match", "--home", "tiki-taka", "--away", "BS"], "unknown strategy 'tiki-taka'"),
        (["match", "--home", "BS"], "required: --away"),
        (["match", "--home", "BS", "--away", "BS", "--bogus"], "unrecognized arguments: --bogus"),
        (["match", "--home", "BS", "--away", "BS", "--link", "5g"], "unknown link preset '5g'"),
        (["match", "--home", "BS", "--away", "BS", "--link-param", "wifi.warp=9"], "unknown link parameter 'warp'"),
        (["match", "--home", "BS", "--away", "BS", "--external", "c/9"], "bad process name"),
        (["match", "--home", "BS", "--away", "BS", "--half-time", "-3"], "give a finite number of seconds > 0"),
        (["run", "robot", "--match", "m", "--connect", "tcp/127.0.0.1:1"], "needs --team"),
        (
            ["run", "robot", "--match", "m/x", "--connect", "tcp/127.0.0.1:1", "--team", "a", "--robot", "1"],
            "bad match id",
        ),
        (
            ["run", "engine", "--match", "m", "--connect", "tcp/127.0.0.1:1", "--config", "/nonexistent.json"],
            "cannot read --config",
        ),
        (["up", "/nonexistent/compose.yaml"], "cannot read"),
        (["match", "--home", "BS", "--away", "BS", "--record", "/nonexistent/dir/m.mcap"], "does not exist"),
        (["review", "/nonexistent.mcap"], "cannot read"),
        (["replay", "/nonexistent.mcap", "--process", "a/1"], "cannot read"),
        (["replay", "/nonexistent.mcap"], "required: --process"),
        (
            [
                "run",
                "robot",
                "--match",
                "m",
                "--connect",
                "tcp/127.0.0.1:1",
                "--team",
                "a",
                "--robot",
                "1",
                "--record",
                "x.mcap",
            ],
            "--record does not apply",
        ),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args, needle, capfd):
    r = arena(*args) if args == ["frobnicate"] else arena_in_process(args, capfd)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "Traceback" not in r.stderr


def test_help_texts_show_examples(capfd):
    for cmd in ("match", "run", "up", "bench", "review", "replay"):
        r = arena_in_process([cmd, "--help"], capfd)
        assert r.returncode == 0 and "examples:" in r.stdout


def test_arena_up_help_says_how_long_it_plays_and_which_variables_change_it(capfd):
    """`arena up` played 2 x 300 s, and ARENA_HALF_TIME was documented only in a compose.yaml comment."""
    out = arena_in_process(["up", "--help"], capfd).stdout
    assert "2 x 300 s" in out
    for var in ("ARENA_HALF_TIME", "ARENA_HOME", "ARENA_AWAY", "ARENA_SEED", "ARENA_LINK", "ARENA_MATCH"):
        assert var in out, var
