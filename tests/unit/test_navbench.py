"""`arena bench nav` (experiments/navbench/): scenario files, determinism, paper 3's local minima, output shape.

Safe rates are measurements, reported by the benchmark and docs/navigation.md;
they are not asserted here. What is asserted is what the issue claims as fact
(MAPF gets out of SAROG and GNRON, APF does not get out of GNRON) and the
benchmark's own contract.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from arena.experiments import navbench as nb
from arena.navigation import fsfm
from tests.integration.helpers import arena_in_process

MINI = """
[[scenario]]
name = "mine"
start = [-1.5, 0.0]
target = [1.5, 0.0]
time_limit = 6.0
obstacles = [{ start = [0.0, 0.3] }, { start = [0.5, -2.0], velocity = [0.0, 1.0] }]
schemes = ["#1", "#5"]
"""


def write(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def arena(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arena", *args], capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def spec() -> nb.BenchSpec:
    return nb.load()


# ------------------------------------------------------------ scenario files
def test_the_builtin_file_holds_the_papers_experiments(spec):
    assert [s.name for s in spec.scenarios] == ["static", "crossing", "pursuit"]
    assert [m.name for m in spec.local_minima] == ["SAROG", "GNRON"]
    schemes = {s.name: s for s in spec.scenarios[0].schemes}
    assert [schemes[n].method for n in ("#1", "#2", "#3", "#4", "#5", "#6", "MAPF")] == [
        "sfm",
        "sfm",
        "apf",
        "apf",
        "f-sfm",
        "f-sfm",
        "mapf",
    ]
    assert (schemes["#1"].params.k, schemes["#2"].params.k) == (100.0, 300.0)
    assert (schemes["#3"].params.k_r, schemes["#4"].params.k_r) == (100.0, 300.0)
    assert schemes["#5"].params.fis.outputs == fsfm.SCHEME_5
    assert schemes["#6"].params.fis.outputs == fsfm.SCHEME_6
    assert schemes["#6"].params.fis.table[0][0] == 600.0  # the FIS's rule table follows the outputs
    sfm = schemes["#1"].params  # paper 1 Table 1
    assert (sfm.mass, sfm.tau, sfm.max_speed, sfm.robot_radius, sfm.sigma) == (20.0, 0.1, 2.0, 0.5, 0.5)
    sc = spec.scenarios[0]
    assert sc.robot.model == "omni3" and sc.robot.mass == 20.0
    assert sc.spec.reference["#3"].free == 3
    gnron = spec.local_minima[1]
    assert gnron.robot.model == "diff" and gnron.spec.obstacles == [(1.3, 0.0)]
    assert dict(gnron.methods)["mapf"].n == 5.0


def test_a_user_file_adds_a_scenario_without_code(tmp_path):
    spec = nb.load(write(tmp_path, MINI))
    (sc,) = spec.scenarios
    assert spec.local_minima == ()
    assert sc.spec.dt == 0.05 and sc.spec.noise.sensor  # from the built-in [defaults]
    assert [s.name for s in sc.schemes] == ["#1", "#5"]
    report = nb.run_bench(spec, trials=1)
    rows = nb.results_rows(report)
    assert [(r["scenario"], r["scheme"]) for r in rows] == [("mine", "#1"), ("mine", "#5")]
    assert all(r["paper_avg_iterations"] is None for r in rows)


def test_user_defaults_override_the_builtin_ones_key_by_key(tmp_path):
    text = "[defaults]\nrobot_params = { max_accel = 4.0 }\n[defaults.noise]\nsensor = false\n" + MINI
    (sc,) = nb.load(write(tmp_path, text)).scenarios
    assert sc.robot.max_accel == 4.0 and sc.robot.mass == 20.0
    assert not sc.spec.noise.sensor and sc.spec.noise.obstacle_start_sigma == 0.1


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("this is = = not toml", "not valid TOML"),
        ("[defaults]\ndt = 0.05\n", "no [[scenario]] or [[local_minimum]] table"),
        (MINI.replace("start = [-1.5, 0.0]", "start = [-1.5]"), "scenario[0].start"),
        (MINI.replace('name = "mine"', 'name = "mine"\ncolour = "red"'), "unknown field `colour`"),
        (MINI.replace("time_limit = 6.0", 'time_limit = "long"'), "Expected `float`, got `str`"),
        (MINI.replace('"#5"]', '"#9"]'), "unknown scheme '#9'"),
        (MINI.replace('name = "mine"', 'name = "mine"\nrobot = "R2D2"'), "unknown robot 'R2D2'"),
        (MINI.replace('name = "mine"', 'name = "mine"\nrobot = "EPUCK"'), "does not fit robot model 'diff'"),
        (MINI.replace("[1.5, 0.0]", "[9.5, 0.0]"), "off the 12 m x 8 m field"),
        (MINI.replace("time_limit = 6.0", "time_limit = -1.0"), "must be > 0"),
        (MINI + '[[scheme]]\nname = "#1"\nmethod = "sfm"\nparams = { kk = 1.0 }\n', "unknown parameter 'kk'"),
        (MINI + '[[scheme]]\nname = "#1"\nmethod = "rrt"\n', "unknown method 'rrt'"),
        (MINI + '[[scheme]]\nname = "#1"\nmethod = "sfm"\nparams = { k = "big" }\n', "expected float"),
        (
            MINI.replace("time_limit = 6.0", "time_limit = 6.0\nrobot_params = { wings = 2 }"),
            "unknown parameter 'wings'",
        ),
        (
            MINI.replace(
                "obstacles = [", "obstacles = [{ start = [0.0, 1.0], velocity = [1.0, 0.0], pursue_speed = 1.0 }, "
            ),
            "both velocity and pursue_speed",
        ),
    ],
)
def test_a_malformed_file_gives_one_clear_line(tmp_path, text, needle):
    with pytest.raises(nb.ScenarioError) as err:
        nb.load(write(tmp_path, text))
    message = str(err.value)
    assert needle in message
    assert "\n" not in message
    assert str(tmp_path) in message  # names the file


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(nb.ScenarioError, match="no such file"):
        nb.load(tmp_path / "nope.toml")
    with pytest.raises(nb.ScenarioError, match="is a directory"):
        nb.load(tmp_path)


def test_the_cli_reports_a_missing_file_in_one_line_with_exit_2():
    r = arena("bench", "nav", "--scenarios", "/nonexistent/scenarios.toml")  # a real process: its exit and stderr
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip() == "arena bench: error: --scenarios /nonexistent/scenarios.toml: no such file"


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--scenarios", "BROKEN"], "not valid TOML"),
        (["--trials", "0"], "--trials: '0': give 1 or more"),
        (["--only", "penalty"], "--only penalty: no such scenario"),
        (["--plots", "FILE"], "exists and is not a directory"),
    ],
)
def test_the_cli_reports_bad_input_in_one_line_with_exit_2(tmp_path, capsys, args, needle):
    from arena import cli

    swap = {"BROKEN": str(write(tmp_path, "[[scenario]\n")), "FILE": str(write(tmp_path, "", "plots.png"))}
    assert cli.main(["bench", "nav", *(swap.get(a, a) for a in args)]) == 2
    err = capsys.readouterr().err
    assert needle in err
    assert len(err.strip().splitlines()) == 1, err


# -------------------------------------------------------------- determinism
def test_the_same_seed_gives_the_same_trial_step_by_step(spec):
    sc = next(s for s in spec.scenarios if s.name == "crossing")
    scheme = next(s for s in sc.schemes if s.name == "#5")
    a, b = nb.run_trial(sc, scheme, 3, seed=11), nb.run_trial(sc, scheme, 3, seed=11)
    assert a.robot_xy.shape == b.robot_xy.shape, "trial lengths differ"
    for i, (pa, pb) in enumerate(zip(a.robot_xy, b.robot_xy)):
        assert np.array_equal(pa, pb), f"robot position differs first at iteration {i}"
    assert a.outcome() == b.outcome()
    c = nb.run_trial(sc, scheme, 3, seed=12)
    assert c.outcome() != a.outcome(), "another seed should give another trial"


def test_every_scheme_meets_the_same_obstacles_in_a_trial(spec):
    """Common random numbers: the trial's noise does not depend on the scheme."""
    sc = next(s for s in spec.scenarios if s.name == "static")
    starts = {s.name: nb.run_trial(sc, s, 2, seed=5).obstacles_xy[0] for s in sc.schemes[:3]}
    first = next(iter(starts.values()))
    assert all(np.array_equal(first, v) for v in starts.values())
    assert not np.array_equal(first, nb.run_trial(sc, sc.schemes[0], 3, seed=5).obstacles_xy[0])


def test_contacts_are_the_engines_collisions(tmp_path):
    """An APF that never repels drives into the obstacle on its path; one far off the path is never touched."""
    text = (
        MINI.replace('schemes = ["#1", "#5"]', 'schemes = ["blind"]')
        .replace("{ start = [0.0, 0.3] }", "{ start = [0.0, 0.0] }")
        .replace("{ start = [0.5, -2.0], velocity = [0.0, 1.0] }", "{ start = [0.0, 3.5] }")
    )
    text = "[defaults.noise]\nsensor = false\nobstacle_start_sigma = 0.0\n" + text
    text += '[[scheme]]\nname = "blind"\nmethod = "apf"\nparams = { safe_distance = 0.001 }\n'
    (sc,) = nb.load(write(tmp_path, text)).scenarios
    t = nb.run_trial(sc, sc.schemes[0], 0)
    assert t.collisions >= 1 and t.min_clearance < 0.01
    assert all(abs(y) < 0.5 for _, y in t.collision_xy)


# ---------------------------------------------------- paper 3's local minima
@pytest.fixture(scope="module")
def minima(spec) -> dict[tuple[str, str], nb.Trial]:
    return {(lm.name, m): nb.run_local_minimum(lm, m, p) for lm in spec.local_minima for m, p in lm.methods}


def test_mapf_gets_out_of_sarog_and_gnron(minima):
    for env in ("SAROG", "GNRON"):
        t = minima[(env, "mapf")]
        assert t.reached and t.collisions == 0, env
        assert t.min_clearance > 0.0, env


def test_plain_apf_does_not_reach_the_goal_in_gnron(minima):
    t = minima[("GNRON", "apf")]
    assert not t.reached
    assert np.hypot(*(t.robot_xy[-1] - (1.5, 0.0))) > 0.1  # held off by the obstacle 0.2 m from the goal


# ------------------------------------------------------------------ output
def test_json_has_the_issues_shape(capfd):
    r = arena_in_process(["bench", "nav", "--trials", "1", "--only", "static,SAROG", "--json"], capfd)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert {"results", "mapf", "timing", "methods"} <= set(out)
    assert len(out["results"]) == 7
    for row in out["results"]:
        assert {"scenario", "method", "scheme", "safe_rate", "avg_iterations", "us_per_iteration"} <= set(row)
        assert row["method"] in ("apf", "sfm", "f-sfm", "mapf")
        assert 0.0 <= row["safe_rate"] <= 1.0 and row["us_per_iteration"] > 0
    assert [(m["env"], m["method"]) for m in out["mapf"]] == [("SAROG", "apf"), ("SAROG", "mapf")]
    for row in out["mapf"]:
        assert {"env", "method", "reached", "path_length_m", "min_clearance_m"} <= set(row)
        assert isinstance(row["reached"], bool)
    assert out["timing"]["fis_overhead_step_percent"] is not None


def test_tables_and_plots(tmp_path, spec, capsys):
    from rich.console import Console

    report = nb.run_bench(nb.select(spec, ["pursuit", "GNRON"]), trials=1)
    nb.print_report(report, Console(width=160, file=sys.stdout))
    text = capsys.readouterr().out
    assert "pursuit" in text and "Table 6" in text and "GNRON" in text and "F-SFM over SFM" in text
    paths = nb.write_plots(report, tmp_path / "plots")
    assert sorted(p.name for p in paths) == ["nav_local_minima.png", "nav_pursuit.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in paths)
