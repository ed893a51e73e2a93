"""Scenario files, expectations, `arena scenario run` and the pytest plugin (scenarios/, docs/scenarios.md)."""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from arena.cli import main
from arena.recording.reader import load as load_recording
from arena.scenarios import ScenarioError, load, load_all, wilson
from arena.scenarios.expect import Trace, judge
from arena.scenarios.model import Expect, When
from arena.schemas.messages import BallEvent, RefCommand, RobotState, World

pytest_plugins = ["pytester"]

ROLL_IN = """
[[scenario]]
name = "roll-in"
time_limit = 2.0
[scenario.start]
ball = { x = 4.0, y = 0.0, vx = 4.0, vy = 0.0 }
robots = [{ robot = "b/0", present = false }]
[[scenario.expect]]
name = "a scores"
kind = "goal"
team = "a"
within = 1.0
[[scenario.expect]]
name = "kick-off spot"
kind = "command"
command = "KICKOFF"
team = "b"
region = [-0.1, -0.1, 0.1, 0.1]
"""

NEVER = ROLL_IN.replace('name = "roll-in"', 'name = "never"').replace(
    'kind = "goal"', 'kind = "never_command"\ncommand = "GOAL"'
)


@pytest.fixture
def files(tmp_path):
    (tmp_path / "ok.scenario.toml").write_text(ROLL_IN)
    (tmp_path / "bad.scenario.toml").write_text(NEVER)
    return tmp_path


# ------------------------------------------------------------------ the file
@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("within = 1.0", 'within = "soon"'), "scenario[0].expect[0].within: expected `float | null`, got `str`"),
        (("within = 1.0", "withn = 1.0"), "scenario[0].expect[0]: object contains unknown field `withn`"),
        (('kind = "goal"', 'kind = "goals"'), "scenario[0].expect[0].kind: 'goals' is not one of goal,"),
        (('team = "a"', 'team = ""'), "scenario[0].expect[0].team: the kind goal needs it"),
        (('"b/0"', '"b/7"'), "scenario[0].start.robots[0].robot: 'b/7' is not a robot of this match"),
        (("time_limit = 2.0", "time_limit = -2.0"), "scenario[0].time_limit: a positive number of seconds"),
        (("region = [-0.1, -0.1, 0.1, 0.1]", "region = [1, 2]"), "scenario[0].expect[1].region: [x0, y0, x1, y1]"),
        (
            (
                "[scenario.start]",
                "[[scenario.step]]\nat = 1\nwhen = { possession = 'a' }\npark = ['a/1']\n[scenario.start]",
            ),
            "scenario[0].step[0]: give exactly one of `at`",
        ),
        (
            (
                "[scenario.start]",
                "[[scenario.step]]\nwhen = { possession = 'a' }\nreferee = { command = 'STOP' }\n[scenario.start]",
            ),
            "scenario[0].step[0].referee: a referee command needs `at`",
        ),
        (
            ("[scenario.start]", "[scenario.play]\nhome = 'nobody'\n[scenario.start]"),
            "scenario[0].play.home: unknown strategy 'nobody'",
        ),
        # the file's key, not arena match's flag; a bad link preset names the file too
        (("[scenario.start]", "[scenario.play]\nrobots = 7\n[scenario.start]"), "scenario[0].play.robots: must be"),
        (("[scenario.start]", "[scenario.play]\nlink = '5g'\n[scenario.start]"), "scenario[0].play.link: unknown"),
        (("[scenario.start]", "[scenario.play]\nhalf_time = -1.0\n[scenario.start]"), "scenario[0].play.half_time"),
        # a window or a step outside the run: it judged ticks the run never played, or never happened
        (("within = 1.0", "within = 9.0"), "scenario[0].expect[0].within: 9 s is after the run's end (time_limit 2 s)"),
        (("within = 1.0", "within = 1.0\nfrom = 1.5"), "scenario[0].expect[0].from: 1.5 s is after the window's end"),
        (("within = 1.0", "within = 1.0\nuntil = 2.0"), "scenario[0].expect[0]: give `within` or `until`, not both"),
        (
            ("[scenario.start]", "[[scenario.step]]\nat = 3.0\npark = ['a/1']\n[scenario.start]"),
            "scenario[0].step[0].at: 3 s is after the run's end (time_limit 2 s): the step would never happen",
        ),
        # two scenarios of one name: their verdicts were counted together, each twice
        ((ROLL_IN, ROLL_IN + ROLL_IN), "scenario[1].name: 'roll-in' is already scenario[0]'s"),
        # a PENALTY without its team loaded, was rejected three times at run time, and the scenario passed
        (
            ("[scenario.start]", "[[scenario.step]]\nat = 1.0\nreferee = { command = 'PENALTY' }\n[scenario.start]"),
            "scenario[0].step[0].referee.team: PENALTY needs the team it is for (a or b)",
        ),
        # start.clock near the end: the run ends early; a window after that end judged ticks that never ran
        (
            ("[scenario.start]", "[scenario.start]\nclock = 599.5"),
            "scenario[0].expect[0].within: 1 s is after the run's end (the match ends 0.5 s in (start.clock 599.5 s",
        ),
        (
            ("[scenario.start]", "[[scenario.step]]\nat = 1.5\npark = ['a/1']\n[scenario.start]\nclock = 599.0"),
            "scenario[0].step[0].at: 1.5 s is after the run's end (the match ends 1 s in",
        ),
        # a digest of a process that does not exist failed only at run time
        (
            ('kind = "goal"\nteam = "a"', 'kind = "digest"\nprocess = "robot/a/9"\ndigest = "ab"'),
            "scenario[0].expect[0].process: 'robot/a/9' is not a process of this match",
        ),
        # a reversed region was silently normalised
        (
            ("region = [-0.1, -0.1, 0.1, 0.1]", "region = [0.1, -0.1, -0.1, 0.1]"),
            "scenario[0].expect[1].region: [x0, y0, x1, y1] with x0 <= x1 and y0 <= y1",
        ),
        # numbers out of range reached the physics or ran for ever
        (("x = 4.0, y = 0.0", "x = 50.0, y = 0.0"), "scenario[0].start.ball.x: a number in [-6.89, 6.89] m (inside"),
        (("x = 4.0, y = 0.0", "x = nan, y = 0.0"), "scenario[0].start.ball.x: a number in"),
        (("x = 4.0, y = 0.0", "x = 4.0, y = inf"), "scenario[0].start.ball.y: a number in"),
        (("vx = 4.0", "vx = 1e308"), "scenario[0].start.ball.vx: a number in [-20, 20] m/s"),
        (("time_limit = 2.0", "time_limit = 1e308"), "scenario[0].time_limit: a positive number of seconds, at most"),
        (
            ('robot = "b/0", present = false', 'robot = "b/0", x = 1e308'),
            "scenario[0].start.robots[0].x: a number in [-6.775, 6.775] m (inside the fence)",
        ),
        # the keys of a scenario at the top of the file: "unknown field `name`" did not say where they belong
        (
            ("[[scenario]]\n", ""),
            "`name`, `time_limit` belong in a [[scenario]] table: put the line [[scenario]] above them",
        ),
    ],
)
def test_a_bad_file_is_one_line_naming_the_key(tmp_path, capsys, change, message):
    path = tmp_path / "x.scenario.toml"
    path.write_text(ROLL_IN.replace(*change))
    with pytest.raises(ScenarioError, match="^" + str(path).replace(".", r"\.") + ": ") as err:
        load_all(path)
    assert message in str(err.value) and "\n" not in str(err.value)
    assert main(["scenario", "run", str(path)]) == 2
    err_line = capsys.readouterr().err
    assert err_line.count("\n") == 1 and message in err_line


def test_the_start_becomes_steps_at_tick_zero(files):
    sc = load(files / "ok.scenario.toml")
    cfg = sc.config(seed=5)
    assert cfg.seed == 5 and cfg.total_ticks == 100 and cfg.scenario.stage == "FIRST_HALF"
    (step,) = cfg.scenario.steps
    assert step.at == 0 and [type(a).__name__ for a in step.actions] == [
        "TeleportRobot",
        "TeleportBall",
        "RefereeOverride",
    ]


def test_wilson_interval():
    assert wilson(0, 1) == (0.0, pytest.approx(0.7935, abs=1e-4))
    assert wilson(3, 3)[0] == pytest.approx(0.4385, abs=1e-4)
    lo, hi = wilson(8, 10)
    assert lo == pytest.approx(0.4902, abs=1e-4) and hi == pytest.approx(0.9433, abs=1e-4)


# ------------------------------------------------------------ expectations
def world(tick, bx, by, robots=(), has=None):
    rs = [RobotState(team=t, robot=n, x=x, y=y, theta=0.0, has_ball=(t, n) == has) for t, n, x, y in robots]
    last = ("a", 1) if 30 <= tick < 60 else ("b", 1) if tick >= 60 else ("", -1)
    return World(
        tick=tick,
        t=tick * 0.02,
        ball_x=bx,
        ball_y=by,
        ball_vx=0.25 * tick if tick <= 20 else 0.0,
        robots=rs,
        last_team=last[0],
        last_robot=last[1],
    )


TRACE = Trace(
    dt=0.02,
    worlds=[
        world(k, 0.1 * k, 0.0, [("a", 1, 0.02 * k, 1.0), ("b", 1, 2.5, 1.0)], ("a", 1) if k > 50 else None)
        for k in range(101)
    ],
    commands=[RefCommand(name="CORNER", team="a", x=5.75, y=3.75, tick=40), RefCommand(name="GOAL", team="b", tick=90)],
    digests={"engine": "abcdef0123"},
    events=[
        BallEvent(kind="TOUCH", tick=30, team="a", robot=1),
        BallEvent(kind="FOUL_PUSHING", tick=70, team="b", robot=1, x=1.0, y=1.0),
    ],
    scores=[(k, 0, 1 if k >= 90 else 0) for k in range(0, 101, 5)],
)


@pytest.mark.parametrize(
    ("fields", "ok", "tick"),
    [
        (dict(kind="goal", team="b"), True, 90),
        (dict(kind="goal", team="b", within=1.0), False, 50),
        (dict(kind="goal", team="a"), False, 100),
        (dict(kind="command", command="CORNER", region=[5.5, 3.5, 6.0, 4.0]), True, 40),
        (dict(kind="command", command="CORNER", region=[-6.0, 3.5, -5.5, 4.0]), False, 100),
        (dict(kind="never_command", command="GOAL", team="a"), True, 100),
        (dict(kind="never_command", command="GOAL"), False, 90),
        (dict(kind="ball_in", region=[5.0, -1.0, 6.0, 1.0]), True, 50),
        (dict(kind="ball_never_in", region=[5.0, -1.0, 6.0, 1.0], until=0.9), True, 45),
        (dict(kind="ball_never_in", region=[5.0, -1.0, 6.0, 1.0]), False, 50),
        (dict(kind="robot_in", robot="a/1", region=[1.0, 0.0, 2.0, 2.0]), True, 50),
        (dict(kind="robot_never_in", robot="b/1", region=[2.0, 0.0, 4.0, 2.0], **{"from_": 1.0}), False, 50),
        (dict(kind="possession", team="a"), True, 51),
        (dict(kind="possession", team="b"), False, 100),
        (dict(kind="min_distance", distance=1.0), False, 76),
        (dict(kind="min_distance", distance=1.0, until=1.5), True, 75),
        (dict(kind="not_stuck", seconds=1.0), False, 51),
        (dict(kind="not_stuck", seconds=1.0, robots=["a/1"]), True, 100),
        (dict(kind="digest", process="engine", digest="abcd"), True, 100),
        (dict(kind="digest", process="engine", digest="abce"), False, 100),
        (dict(kind="ball_speed", speed=4.0), True, 17),
        (dict(kind="ball_speed", speed=4.0, until=0.3), False, 15),
        (dict(kind="ball_never_faster", speed=6.0), True, 100),
        (dict(kind="ball_never_faster", speed=2.0), False, 9),
        (dict(kind="last_touch", team="b"), True, 100),
        (dict(kind="last_touch", team="a", until=1.0), True, 50),
        (dict(kind="last_touch", robot="a/1"), False, 100),
        (dict(kind="score", score=[0, 1]), True, 100),
        (dict(kind="score", score=[0, 1], until=1.0), False, 50),
        (dict(kind="event", event="FOUL_PUSHING", team="b"), True, 70),
        (dict(kind="event", event="FOUL_PUSHING", robot="b/2"), False, 100),
        (dict(kind="never_event", event="TOUCH", until=0.5), True, 25),
        (dict(kind="never_event", event="TOUCH"), False, 30),
        # windows from a trigger: the first tick a holds the ball is 51
        (dict(kind="ball_in", region=[5.0, -1.0, 6.0, 1.0], when=When(possession="a")), True, 51),
        (dict(kind="ball_in", region=[5.5, -1.0, 6.0, 1.0], when=When(possession="a"), **{"from_": 0.1}), True, 56),
        (dict(kind="ball_never_in", region=[5.0, -1.0, 6.0, 1.0], when=When(possession="a")), False, 51),
        (dict(kind="goal", team="b", when=When(possession="a"), within=0.7), False, 86),
        (dict(kind="goal", team="b", when=When(possession="a"), within=0.8), True, 90),
        (dict(kind="never_command", command="GOAL", when=When(command="CORNER")), False, 90),
        (dict(kind="possession", team="a", when=When(possession="b")), False, 100),
    ],
)
def test_each_kind_judges_its_window(fields, ok, tick):
    e = Expect(name="x", **fields)
    got_ok, got_tick, detail = judge(e, TRACE, time_limit=2.0)
    assert (got_ok, got_tick) == (ok, tick), detail


# -------------------------------------------------------- arena scenario run
def test_run_passes_fails_and_reports(files, tmp_path, capsys):
    junit = tmp_path / "report.xml"
    records = tmp_path / "runs"
    code = main(
        ["scenario", "run", str(files), "--seeds", "2", "--json", "--junit", str(junit), "--records", str(records)]
    )
    assert code == 1
    out = json.loads(capsys.readouterr().out)
    by_name = {s["scenario"]: s for s in out["scenarios"]}
    assert by_name["roll-in"]["passed"] and by_name["roll-in"]["pass_rate"] == 1.0
    never = by_name["never"]
    assert not never["passed"] and never["wilson95"] == [0.0, pytest.approx(0.6576, abs=1e-4)]
    failure = never["runs"][0]["failures"][0]
    assert failure["name"] == "a scores" and failure["tick"] == 30
    record = never["runs"][0]["record"]
    assert record and load_recording(record).complete, "the failed run's MCAP is whole"
    assert main(["review", record]) == 0 and "basic-static (a) 1 : 0" in capsys.readouterr().out
    cases = ET.parse(junit).getroot().findall("testcase")
    assert sorted(c.get("name") for c in cases) == ["never", "roll-in"]
    assert [c.get("name") for c in cases if c.find("failure") is not None] == ["never"]
    # the printed form names the expectation, the tick, the seed and the replay command
    assert main(["scenario", "run", str(files / "bad.scenario.toml"), "--records", str(records)]) == 1
    text = capsys.readouterr().out
    assert "seed 0: expectation 'a scores' failed at tick 30" in text
    assert "replay: arena scenario run" in text and "--seed 0" in text


def test_reruns_give_identical_verdicts(files):
    from arena.scenarios import run_one

    sc = load(files / "ok.scenario.toml")
    first, again = run_one(sc, 3), run_one(sc, 3)
    assert first == again and first.passed and first.score == (1, 0)
    assert run_one(sc, 4).digest != first.digest


def test_min_pass_decides(files, capsys):
    path = files / "bad.scenario.toml"
    path.write_text(NEVER.replace("time_limit = 2.0", "time_limit = 2.0\nmin_pass = 0.0"))
    assert main(["scenario", "run", str(path)]) == 0
    assert capsys.readouterr().out.startswith("PASS never")


# ------------------------------------------------------------ pytest plugin
def test_the_plugin_collects_one_item_per_scenario(pytester):
    pytester.makefile(".scenario.toml", two=ROLL_IN + NEVER.replace("[[scenario]]", "\n[[scenario]]", 1))
    pytester.makepyfile(
        test_fixture="""
def test_it(arena_scenario):
    outcome = arena_scenario("two.scenario.toml", name="roll-in")
    assert outcome.passed and outcome.rate == 1.0
"""
    )
    result = pytester.runpytest_inprocess("-q", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=2, failed=1)
    result.stdout.fnmatch_lines(["*FAIL never*", "*expectation 'a scores' failed at tick 30*"])
    assert math.isfinite(1.0)


@pytest.mark.parametrize("seeds", ["0", "-2", "many"])
def test_the_plugin_refuses_a_seed_count_below_one(pytester, seeds):
    pytester.makefile(".scenario.toml", one=ROLL_IN)
    result = pytester.runpytest_inprocess("-q", "-p", "no:cacheprovider", "--scenario-seeds", seeds)
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines([f"*--scenario-seeds: expected a whole number >= 1, got '{seeds}'*"])


# ------------------------------------------------------ replay with substitution
def test_a_substituted_team_follows_its_recorded_poses_while_the_rest_plays_live(tmp_path):
    import msgspec

    from arena.config import MatchConfig
    from arena.match.inprocess import play_in_process
    from arena.recording.reader import load as read

    play_in_process(
        MatchConfig(seed=3, home="AD", away="BS", half_time=2.0), watch=(), record=str(tmp_path / "src.mcap")
    )
    recorded = {w.tick: w for w in read(str(tmp_path / "src.mcap"), keep={"world"}).decoded("world", World)}
    path = tmp_path / "sub.scenario.toml"
    path.write_text(
        '[[scenario]]\nname = "sub"\ntime_limit = 1.5\n[scenario.play]\nhome = "chase"\naway = "BS"\n'
        'substitute = { team = "b", recording = "src.mcap", from = 1.0 }\n'
        "[scenario.start]\nball = { x = 1.0, y = 1.0 }\n"
    )
    sc = load(path)
    _, frames = play_in_process(sc.config(0), watch=("world",))
    worlds = [msgspec.msgpack.decode(p, type=World) for p in frames["world"]]
    for w in worlds:
        want = recorded[w.tick + 50]
        assert [(r.x, r.y, r.theta) for r in w.robots if r.team == "b"] == [
            (r.x, r.y, r.theta) for r in want.robots if r.team == "b"
        ], f"tick {w.tick}"
    moved_a = {(r.x, r.y) for w in worlds for r in w.robots if (r.team, r.robot) == ("a", 1)}
    assert len(moved_a) > 10 and any(w.ball_x != recorded[w.tick + 50].ball_x for w in worlds), (
        "a and the ball are live"
    )
    path.write_text(path.read_text().replace("from = 1.0", "from = 9.0"))
    with pytest.raises(ScenarioError, match=r"scenario\[0\]\.play\.substitute\.from: the recording has no world frame"):
        load(path)


# ------------------------------------------------------------- the documentation
DOC = Path(__file__).resolve().parents[2] / "docs" / "scenarios.md"


def test_every_key_and_kind_is_documented():
    import msgspec

    from arena.scenarios import model
    from arena.scenarios.expect import KINDS

    text = DOC.read_text()
    specs = [model.Play, model.Substitute, model.BallSpec, model.RobotSpec, model.RefereeSpec, model.Start]
    specs += [model.When, model.StepSpec, model.LinkSpec, model.Expect, model.ScenarioSpec, model.ControlSpec]
    missing = [
        f"{cls.__name__}.{f.encode_name}"
        for cls in specs
        for f in msgspec.structs.fields(cls)
        if f"`{f.encode_name}`" not in text
    ]
    missing += [f"kind {k}" for k in KINDS if f"`{k}`" not in text]
    assert not missing, f"not in docs/scenarios.md: {missing}"


def test_the_documented_examples_load_and_run(tmp_path):
    from arena.scenarios import run_one

    blocks = re.findall(r"```toml\n(.*?)```", DOC.read_text(), flags=re.S)
    whole = [b for b in blocks if "[[scenario]]" in b]
    parts = [b for b in blocks if "[[scenario]]" not in b and "my-team" not in b]
    assert whole and len(parts) >= 3
    for i, text in enumerate(whole):
        (tmp_path / f"w{i}.scenario.toml").write_text(text)
        assert run_one(load(tmp_path / f"w{i}.scenario.toml"), 0).ticks > 0
    composite = '[[scenario]]\nname = "docs"\ntime_limit = 6.0\n' + "\n".join(parts)
    (tmp_path / "parts.scenario.toml").write_text(composite)
    v = run_one(load(tmp_path / "parts.scenario.toml"), 0)
    assert v.ticks == 300 and "engine digest" in {f.name for f in v.failures}


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["scenario", "run"], "run needs a FILE or DIR"),
        (["scenario", "run", "EXT"], "'ext' has external processes (play.external): run it with --engine processes"),
        (["scenario", "run", "DIR", "--record", "x.mcap"], "--record needs one scenario (--name) and one seed"),
        (["scenario", "run", "DIR", "--name", "nobody"], "no scenario named 'nobody' (it has: never, roll-in)"),
        (["scenario", "run", "DIR", "--seeds", "0"], "expected a whole number 1..100000"),
    ],
)
def test_bad_flags_are_one_line_and_exit_2(files, tmp_path_factory, capsys, argv, message):
    ext = tmp_path_factory.mktemp("ext") / "ext.scenario.toml"
    ext.write_text('[[scenario]]\nname = "ext"\ntime_limit = 1.0\n[scenario.play]\nexternal = ["a/1"]\n')
    argv = [str(ext) if a == "EXT" else str(files) if a == "DIR" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err


def test_a_recording_with_a_kill_step_is_refused_by_replay_with_its_reason(tmp_path, capfd):
    """A kill step cuts its process's loop short; replay would drive it on and every node after would differ."""
    from arena.scenarios.library import RULES
    from tests.integration.helpers import arena_in_process

    mcap = tmp_path / "r19.mcap"
    file = str(RULES / "19-dead-robot.scenario.toml")
    assert arena_in_process(["scenario", "run", file, "--seed", "0", "--record", str(mcap)], capfd).returncode == 0
    r = arena_in_process(["replay", str(mcap), "--process", "all"], capfd)
    assert r.returncode == 2, r.stderr
    assert "scenario killed robot/a/1 at tick 50 (a kill step): only matches without one replay" in r.stderr, r.stderr
