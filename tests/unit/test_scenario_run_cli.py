"""`arena scenario run` in daily use: replay lines that run as printed, progress, the closing line,
Ctrl-C, JUnit; randomised starts; hostile files (docs/scenarios.md)."""

from __future__ import annotations

import json
import os
import shlex
import xml.etree.ElementTree as ET

import pytest

from arena.cli import main
from arena.scenarios import ScenarioError, load, load_all, run_one

FAILS = """
[[scenario]]
name = "fails"
time_limit = 1.0
[scenario.play]
robots = 2
[scenario.start]
ball = { x = 1.0, y = 0.0, vx = 0.0, vy = 0.0 }
[[scenario.expect]]
name = "a scores"
kind = "goal"
team = "a"
"""

PASSES = FAILS.replace('name = "fails"', 'name = "passes"').replace(
    'kind = "goal"\nteam = "a"', 'kind = "never_command"\ncommand = "GOAL"'
)


@pytest.fixture
def failing(tmp_path):
    path = tmp_path / "suite" / "f.scenario.toml"
    path.parent.mkdir()
    path.write_text(FAILS)
    return path


def test_every_replay_line_runs_as_pasted_in_another_directory_and_gives_the_failed_runs_digest(
    failing, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(failing.parent)
    assert main(["scenario", "run", "f.scenario.toml", "--seeds", "5", "--json"]) == 1
    runs = {r["seed"]: r for r in json.loads(capsys.readouterr().out)["scenarios"][0]["runs"]}
    assert [bool(runs[s]["record"]) for s in range(5)] == [True, True, True, False, False], "three are recorded"
    assert main(["scenario", "run", "f.scenario.toml", "--seeds", "5"]) == 1
    lines = [ln.split("replay: ", 1)[1] for ln in capsys.readouterr().out.splitlines() if "replay: " in ln]
    assert len(lines) == 5 and len(set(lines)) == 5
    for seed in (0, 3):  # a recorded run (no --record: its MCAP exists) and one that was not
        argv = shlex.split(lines[seed])
        assert argv[:3] == ["arena", "scenario", "run"] and os.path.isabs(argv[3])
        if seed == 3:
            record = argv[argv.index("--record") + 1]
            assert os.path.isabs(record) and record.endswith("f-fails-seed3.mcap") and not os.path.exists(record)
        elsewhere = tmp_path / f"elsewhere{seed}"
        elsewhere.mkdir()
        monkeypatch.chdir(elsewhere)
        assert main(argv[1:] + ["--json"]) == 1
        again = json.loads(capsys.readouterr().out)["scenarios"][0]["runs"]
        assert [r["seed"] for r in again] == [seed] and again[0]["digest"] == runs[seed]["digest"]
    assert os.path.exists(record), "the replay recorded the run where its line said"


def test_record_makes_its_directory(failing, tmp_path, capsys):
    target = tmp_path / "new" / "deeper" / "run.mcap"
    assert main(["scenario", "run", str(failing), "--seed", "1", "--record", str(target)]) == 1
    assert target.is_file()


def test_progress_on_a_terminal_the_closing_line_and_junit_time_and_classname(tmp_path, capsys, monkeypatch):
    for folder in ("x", "y"):  # two files of one name in different folders
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "same.scenario.toml").write_text(PASSES)
    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    monkeypatch.chdir(tmp_path)
    assert main(["scenario", "run", ".", "--seeds", "2", "--junit", "r.xml"]) == 0
    out, err = capsys.readouterr()
    progress = [ln for ln in err.splitlines() if ln.startswith("[")]
    assert [ln.split("]")[0] for ln in progress] == ["[1/4", "[2/4", "[3/4", "[4/4"], err
    assert "pass passes seed 1" in progress[1]
    last = out.splitlines()[-1]
    assert last.startswith("2 passed, 0 failed in ") and last.endswith(" s (4 runs)"), last
    cases = ET.parse(tmp_path / "r.xml").getroot().findall("testcase")
    assert sorted(c.get("classname") for c in cases) == ["x.same", "y.same"]
    assert all(float(c.get("time")) > 0 for c in cases)


def test_ctrl_c_keeps_the_finished_runs(failing, capsys, monkeypatch):
    import arena.commands.scenario as command

    real, calls = command._job, []

    def job(item):
        calls.append(item[1])
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(item)

    monkeypatch.setattr(command, "_job", job)
    assert main(["scenario", "run", str(failing), "--seeds", "6"]) == 130
    out, err = capsys.readouterr()
    assert "FAIL fails" in out and "0/2 runs passed" in out, out
    assert out.splitlines()[-1].endswith("(2 runs); interrupted: 4 of 6 runs not played"), out
    assert "arena scenario: interrupted" in err


def test_a_substitution_recording_that_ends_mid_run_is_said(tmp_path, capsys):
    from arena.config import MatchConfig
    from arena.match.inprocess import play_in_process

    play_in_process(MatchConfig(seed=3, robots=2, half_time=1.0), watch=(), record=str(tmp_path / "src.mcap"))
    path = tmp_path / "sub.scenario.toml"
    path.write_text(
        '[[scenario]]\nname = "sub"\ntime_limit = 2.0\n[scenario.play]\nrobots = 2\n'
        'substitute = { team = "b", recording = "src.mcap", from = 1.0 }\n'
    )
    assert load(path).notes == (
        "scenario[0].play.substitute: the recording ends 1 s into the run (of 2 s); from there team b plays live",
    )
    assert main(["scenario", "run", str(path)]) == 0
    assert "arena scenario: note: " in capsys.readouterr().err


# ------------------------------------------------------------ randomised starts
RANGED = """
[[scenario]]
name = "ranged"
time_limit = 0.5
[scenario.play]
robots = 2
[scenario.start]
ball = { x = { uniform = [3.0, 5.0] }, y = { uniform = [-1.0, 1.0] }, vx = 0.0, vy = 0.0 }
robots = [{ robot = "a/1", x = { int = [1, 3] }, y = 1.0 }]
[[scenario.step]]
at = { uniform = [0.1, 0.3] }
ball = { vx = { uniform = [-1.0, 1.0] } }
[[scenario.expect]]
name = "never a goal"
kind = "never_command"
command = "GOAL"
"""


def test_ranges_are_drawn_per_seed_the_same_on_every_rerun_and_reported(tmp_path, capsys):
    path = tmp_path / "r.scenario.toml"
    path.write_text(RANGED)
    sc = load(path)
    d0, d1 = sc.drawn(0), sc.drawn(1)
    assert list(d0) == ["start.ball.x", "start.ball.y", "start.robots[0].x", "step[0].at", "step[0].ball.vx"]
    assert d0 == sc.drawn(0) and d0 != d1
    assert 3.0 <= d0["start.ball.x"] <= 5.0 and d0["start.robots[0].x"] in (1, 2, 3)
    v0 = run_one(sc, 0)
    assert v0 == run_one(sc, 0) and v0.drawn == d0 and v0.digest != run_one(sc, 1).digest
    w = sc.config(0).scenario.steps[0].actions
    assert w[0].x == d0["start.robots[0].x"] and round(w[1].x, 6) == d0["start.ball.x"], "the engine gets the draw"
    # in --json and, for a failed run, on the failure line
    assert main(["scenario", "run", str(path), "--seeds", "2", "--json"]) == 0
    runs = json.loads(capsys.readouterr().out)["scenarios"][0]["runs"]
    assert runs[1]["drawn"] == d1
    path.write_text(RANGED.replace('kind = "never_command"', 'kind = "command"'))
    assert main(["scenario", "run", str(path), "--records", str(tmp_path / "runs")]) == 1
    assert f"seed 0 (start.ball.x={d0['start.ball.x']:g}, " in capsys.readouterr().out


def test_the_engines_agree_on_a_ranged_scenario_with_control_and_safe_teleports(tmp_path):
    path = tmp_path / "r.scenario.toml"
    extra = (
        '[[scenario.step]]\nat = 0.1\ncontrol = [{ robot = "b/1", seconds = 0.3, vx = { uniform = [0.5, 1.5] } }]\n'
        'robots = [{ robot = "a/0", x = 0.0, y = 0.0, safely = true }, { robot = "b/0", x = 0.0, y = 0.0 }]\n'
    )
    path.write_text(RANGED.replace("[[scenario.expect]]", extra + "[[scenario.expect]]"))
    sc = load(path)
    a, b = run_one(sc, 2, "inprocess"), run_one(sc, 2, "processes")
    assert (a.digest, a.passed, a.drawn) == (b.digest, b.passed, b.drawn)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("{ uniform = [3.0, 5.0] }", "{ uniform = [5.0, 3.0] }", "start.ball.x.uniform: [low, high] with low <= high"),
        ("{ uniform = [3.0, 5.0] }", "{ uniform = [3.0, 50.0] }", "start.ball.x: a number in [-6.89, 6.89] m"),
        ("{ uniform = [-1.0, 1.0] } }", "{ uniform = [-30.0, 1.0] } }", "step[0].ball.vx: a number in [-20, 20] m/s"),
        ("{ uniform = [0.1, 0.3] }", "{ uniform = [0.1, 3.0] }", "step[0].at: 3 s is after the run's end"),
        ("{ int = [1, 3] }", "{ int = [1, 3], uniform = [1.0, 2.0] }", "a range is { uniform = [a, b] } or { int"),
        ("{ int = [1, 3] }", "{ int = [1, nan] }", "expected `int`"),
    ],
)
def test_a_range_is_checked_at_both_ends(tmp_path, old, new, message):
    path = tmp_path / "r.scenario.toml"
    path.write_text(RANGED.replace(old, new))
    with pytest.raises(ScenarioError) as err:
        load_all(path)
    assert message in str(err.value) and "\n" not in str(err.value), err.value


# ------------------------------------------------------------------ hostile files
def hostile(tmp_path, name: str, text: str | bytes):
    path = tmp_path / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("a = " + "[" * 5000 + "]" * 5000 + "\n", "brackets nested deeper than 16"),
        ("x = { a = " * 900 + "1" + " }" * 900 + "\n", "brackets nested deeper than 16"),
        (b'[[scenario]]\nname = "\xff\xfe"\ntime_limit = 1.0\n', "not UTF-8 text (byte 21)"),
        (
            FAILS.replace("time_limit = 1.0", "time_limit = 1e308"),
            "time_limit: a positive number of seconds, at most 3600",
        ),
        (FAILS.replace("x = 1.0,", "x = nan,"), "start.ball.x: a number in [-6.89, 6.89] m"),
        (FAILS.replace("x = 1.0,", "x = inf,"), "start.ball.x: a number in [-6.89, 6.89] m"),
        (FAILS.replace("x = 1.0,", "x = 1e308,"), "start.ball.x: a number in [-6.89, 6.89] m"),
        (
            FAILS + "[[scenario.step]]\nat = 0.5\npark = ['a/1']\n" * 2001,
            "scenario[0].step: 2001 of them; at most 2000",
        ),
        ("# " + "x" * (1 << 20) + "\n", "larger than 1024 KiB"),
    ],
)
def test_a_hostile_scenario_file_is_one_line_and_exit_2(tmp_path, capsys, content, message):
    path = hostile(tmp_path, "h.scenario.toml", content)
    assert main(["scenario", "run", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "internal error" not in err, err


def test_non_regular_files_are_refused_not_waited_on(tmp_path, capsys):
    fifo = tmp_path / "f.scenario.toml"
    os.mkfifo(fifo)
    assert main(["scenario", "run", str(fifo)]) == 2
    assert "not a regular file" in capsys.readouterr().err
    assert main(["scenario", "run", str(tmp_path)]) == 2, "found in a folder, it is refused the same way"
    assert "not a regular file" in capsys.readouterr().err
    sub = tmp_path / "sub"
    sub.mkdir()
    os.mkfifo(sub / "rec.mcap")
    text = FAILS.replace("robots = 2", 'robots = 2\nsubstitute = { team = "b", recording = "rec.mcap" }')
    assert main(["scenario", "run", str(hostile(sub, "s.scenario.toml", text))]) == 2
    err = capsys.readouterr().err
    assert "play.substitute.recording:" in err and "not a regular file" in err, err


def test_a_score_and_a_link_parameter_may_be_ranges_too(tmp_path):
    path = tmp_path / "s.scenario.toml"
    path.write_text(
        '[[scenario]]\nname = "x"\ntime_limit = 1.0\n[scenario.start]\nscore = [{ int = [0, 3] }, 1]\n'
        '[[scenario.step]]\nat = 0.5\nlink = { preset = "wifi", overrides = { wifi = { latency_ms = '
        "{ uniform = [10.0, 80.0] } } } }\n"
    )
    sc = load(path)
    drawn = sc.drawn(1)
    assert set(drawn) == {"start.score[0]", "step[0].link.overrides.wifi.latency_ms"}
    assert run_one(sc, 1).score == (drawn["start.score[0]"], 1)
    link = sc.config(1).scenario.steps[-1].actions[0]
    assert link.overrides["wifi"]["latency_ms"] == pytest.approx(drawn["step[0].link.overrides.wifi.latency_ms"])
