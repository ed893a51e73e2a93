"""`arena experiment tune`: SPSA converges on a noisy function; a small tune runs, writes its files, resumes."""

from __future__ import annotations

import json
import random

import pytest

from arena.experiments import spsa, tune
from arena.strategies.base import Param
from tests.integration.helpers import arena_in_process


def _spsa_maximise(target: list[float], iterations: int, noise: float, seed: int) -> list[float]:
    """SPSA ascent on f(theta) = -3 * sum (theta - target)^2 + noise, from the middle of the box."""
    rng = random.Random(seed)
    f = lambda th: -3.0 * sum((t - g) ** 2 for t, g in zip(th, target)) + rng.gauss(0.0, noise)
    gains = spsa.Gains(a=0.05, c=0.1, A=iterations / 10)
    theta = [0.5] * len(target)
    for k in range(iterations):
        d = spsa.delta(seed, k, len(theta))
        plus, minus = spsa.perturbed(theta, d, gains.c_k(k))
        theta = spsa.step(theta, d, k, f(plus), f(minus), gains)
    return theta


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_spsa_converges_on_a_noisy_quadratic(seed):
    target = [0.2, 0.8, 0.35, 0.6]
    theta = _spsa_maximise(target, iterations=3000, noise=0.3, seed=seed)
    assert max(abs(t - g) for t, g in zip(theta, target)) < 0.1, theta  # from 0.3 off


def test_spsa_without_steps_stays_where_it_started():
    """The test above can fail: with no iterations the middle of the box is 0.3 from the target."""
    theta = _spsa_maximise([0.2, 0.8], iterations=0, noise=0.3, seed=0)
    assert theta == [0.5, 0.5]


def test_the_gain_sequences_are_spalls():
    g = spsa.Gains(a=0.5, c=0.2, A=10)
    assert g.c_k(0) == pytest.approx(0.2) and g.c_k(9) == pytest.approx(0.2 / 10**0.101)
    assert g.a_k(0) == pytest.approx(0.5 / 11**0.602) and g.a_k(4) == pytest.approx(0.5 / 15**0.602)


def test_the_perturbation_depends_on_the_seed_and_iteration_alone():
    assert spsa.delta(3, 7, 5) == spsa.delta(3, 7, 5)
    draws = {tuple(spsa.delta(3, k, 8)) for k in range(20)}
    assert len(draws) > 15 and all(set(d) <= {-1, 1} for d in draws)


def test_the_space_maps_each_range_to_the_unit_interval():
    space = spsa.Space(
        (
            Param("speed", default=2.0, low=1.0, high=5.0, meaning="m"),
            Param("count", default=3, low=0, high=10, meaning="m"),
        )
    )
    assert space.to_unit(space.defaults()) == [0.25, 0.3]
    assert space.values([1.2, 0.46]) == {"speed": 5.0, "count": 5}  # clipped; an int rounded
    assert space.values([0.0, 0.0]) == {"speed": 1.0, "count": 0}


def test_a_bootstrap_interval_brackets_the_mean_and_narrows_with_more_seeds():
    rng = random.Random(0)
    few = [rng.gauss(0.5, 1.0) for _ in range(5)]
    many = [rng.gauss(0.5, 1.0) for _ in range(200)]
    lo, hi = tune.bootstrap_ci(few, 0)
    assert lo <= tune.mean(few) <= hi
    lo2, hi2 = tune.bootstrap_ci(many, 0)
    assert hi2 - lo2 < hi - lo and lo2 < 0.5 < hi2


def _tune(out, *extra, capfd):
    argv = ["experiment", "tune", "--strategy", "AD", "--opponents", "BS", "--params", "kick_speed,keeper_gain"]
    argv += ["--half-time", "15", "--remeasure", "2", "--jobs", "1", "--out", str(out), "--json", *extra]
    return arena_in_process(argv, capfd)


def test_a_small_tune_writes_its_files_and_resumes(tmp_path, capfd):
    out = tmp_path / "t"
    r = _tune(out, "--iterations", "1", capfd=capfd)
    assert r.returncode == 0, r.stderr
    first = json.loads(r.stdout)
    for name in ("tune.json", "history.csv", "result.json", "report.md", "trace.png"):
        assert (out / name).stat().st_size > 0, name
    rm = first["remeasure"]
    assert rm["seeds"] == [tune.REMEASURE_FROM, tune.REMEASURE_FROM + 1] and rm["matches"] == 8
    assert rm["ci95"][0] <= rm["gain"] <= rm["ci95"][1]
    assert set(first["best"]) == {"kick_speed", "keeper_gain"} and 2.0 <= first["best"]["kick_speed"] <= 8.0
    state = json.loads((out / "tune.json").read_text())
    it = state["iterations"][0]
    assert it["seeds"] == [0] and it["plus"] != it["minus"]  # both perturbations played on the same seed
    r = _tune(out, "--iterations", "2", "--resume", capfd=capfd)
    assert r.returncode == 0, r.stderr
    again = json.loads((out / "tune.json").read_text())
    assert len(again["iterations"]) == 2 and again["iterations"][0] == it  # the first iteration kept, not replayed
    assert again["iterations"][1]["seeds"] == [1]
    assert (out / "history.csv").read_text().count("\n") == 3
    r = _tune(out, "--iterations", "2", "--resume", "--seed", "5", capfd=capfd)
    assert r.returncode == 2 and "other settings (seed differ)" in r.stderr


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--params", "kick_sped"], "advance-dynamic's parameters are kick_speed"),
        (["--params", "navigator"], "SPSA tunes numbers only; navigator is str"),
        (["--c", "0.9"], "--c in (0, 0.5]"),
        (["--seed", "999999", "--iterations", "5"], "tuning seeds must stay within"),
        (["--remeasure", "1"], "--remeasure at least 2"),
    ],
)
def test_bad_tune_flags_are_one_line_and_exit_2(tmp_path, capfd, extra, needle):
    argv = ["experiment", "tune", "--strategy", "AD", "--opponents", "BS", "--out", str(tmp_path / "t"), *extra]
    r = arena_in_process(argv, capfd)
    assert r.returncode == 2 and needle in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_optuna_tries_the_defaults_first_and_takes_a_string_parameter(tmp_path, capfd):
    pytest.importorskip("optuna")
    out = tmp_path / "o"
    argv = ["experiment", "tune", "--strategy", "AS", "--opponents", "BS", "--params", "navigator,kick_speed"]
    argv += ["--method", "optuna", "--iterations", "2", "--half-time", "5", "--remeasure", "2", "--jobs", "1"]
    r = arena_in_process([*argv, "--out", str(out), "--json"], capfd)
    assert r.returncode == 0, r.stderr
    state = json.loads((out / "tune.json").read_text())
    assert state["iterations"][0]["values"] == {"navigator": "f-sfm", "kick_speed": 8.0}
    assert [it["seeds"] for it in state["iterations"]] == [[0], [0]]  # every trial the same seeds
    assert json.loads(r.stdout)["best"]["navigator"] in ("apf", "mapf", "sfm", "f-sfm")
