"""The experiment file (experiments/design.py): strict parsing, dotted paths over any
configuration field, the designs, and the matches (common seeds, ends swapped)."""

from __future__ import annotations

import os

import pytest

from arena.config import ConfigError, MatchConfig
from arena.experiments import design


def write(tmp_path, text: str, name: str = "exp.toml") -> str:
    p = tmp_path / name
    p.write_text(text)
    return str(p)


BASE = '[base]\nhome = "AD"\naway = "BS"\nhalf_time = 10.0\n'


def test_two_factors_grid_every_cell_and_match(tmp_path):
    exp = design.load(
        write(
            tmp_path,
            "seeds = 4\n" + BASE + '[factors]\n"links.wifi.latency_ms" = [0, 50, 100]\n'
            '"rules.setpiece_distance" = [2.0, 2.5, 3.0]\n',
        )
    )
    assert len(exp.cells) == 9
    assert exp.cells[4] == {"links.wifi.latency_ms": 50, "rules.setpiece_distance": 2.5}
    cfg = exp.configs[4]
    assert cfg.link_overrides == {"wifi": {"latency_ms": 50.0}} and cfg.rules.setpiece_distance == 2.5
    assert (cfg.home, cfg.away, cfg.half_time) == ("advance-dynamic", "basic-static", 10.0)
    matches = exp.matches()
    assert len(matches) == 9 * 4 * 2
    for c in range(9):  # the same seeds in every cell (common random numbers), both ends each
        mine = [(m["seed"], m["team"]) for m in matches if m["cell"] == c]
        assert mine == [(s, t) for s in range(4) for t in "ab"]
    a, b = (exp.match_config(m) for m in matches[:2])
    assert (a.home, a.away, a.seed) == ("advance-dynamic", "basic-static", 0)
    assert (b.home, b.away, b.seed) == ("basic-static", "advance-dynamic", 0)
    assert b.rules == a.rules and b.link_overrides == a.link_overrides


def test_any_field_by_path_with_its_type(tmp_path):
    exp = design.load(
        write(
            tmp_path,
            BASE + '[factors]\n"timing.perception_latency" = [0, 5]\n"robot.mass" = [30]\n"field.length" = [14.0]\n'
            'away = ["AS"]\n"links.preset" = ["lan"]\nhalf_time = [20]\n',
        )
    )
    cfg = exp.configs[1]
    assert cfg.timing.perception_latency == 5 and cfg.robot.mass == 30.0 and cfg.field.length == 14.0
    assert cfg.away == "advance-static" and cfg.link == "lan" and cfg.half_time == 20.0
    assert isinstance(cfg.robot.mass, float)


def test_an_open_dict_field_takes_new_keys(monkeypatch):
    tree = design.tree_of(MatchConfig())
    design.set_path(tree, "link_overrides.wired.latency_ms", 2.5, "x")
    assert tree["link_overrides"] == {"wired": {"latency_ms": 2.5}}
    with pytest.raises(ConfigError, match="give link_overrides and 2 keys"):
        design.set_path(tree, "link_overrides.wired", 2.5, "x")


@pytest.mark.parametrize(
    "text, error",
    [
        ("bogus = 1\n", "unknown key 'bogus'"),
        ('[factors]\n"rules.no_such" = [1]\n', "factors.rules.no_such: no such configuration field"),
        ('[factors]\n"seed" = [1, 2]\n', "factors.seed: no such configuration field"),
        ('[factors]\n"rules" = [1]\n', "a table; vary one of its keys"),
        ('[factors]\n"timing.perception_latency" = [1.5]\n', "give an integer"),
        ('[factors]\n"robot.mass" = ["heavy"]\n', "give a number"),
        ('[factors]\n"links.wifi.latency_ms" = [-5.0]\n', "links"),
        ('[factors]\n"links.radio.latency_ms" = [5.0]\n', "links"),
        ('[factors]\n"rules.setpiece_distance" = {uniform = [3, 2]}\n', "give levels"),
        ('[factors]\n"rules.setpiece_distance" = {normal = [3, 2]}\n', "give levels"),
        ('[factors]\n"rules.setpiece_distance" = {uniform = [1, 2]}\n', "needs design.kind random or lhs"),
        ('[factors]\n"rules.setpiece_distance" = [nan]\n', "not a finite number"),
        ("[base]\nhalf_time = inf\n", "not a finite number"),
        ("[base]\nseed = 3\n", "the seeds are the experiment's"),
        ("[base]\nfield = 3\n", "field must be a table"),
        ('[factors]\nhome = ["no-such-strategy"]\n', "unknown strategy"),
        ("seeds = 0\n", "seeds must be an integer 1"),
        ('[design]\nkind = "sobol"\n', "design.kind must be one of"),
        ('responses = ["elo"]\n', "unknown response 'elo'"),
        ('opponents = ["BS"]\n[base]\nhome = "BS"\n', "no match to play"),
    ],
)
def test_bad_files_are_one_line_errors(tmp_path, text, error):
    with pytest.raises(ConfigError, match=error) as got:
        design.load(write(tmp_path, text))
    assert "\n" not in str(got.value)


def test_oversize_and_irregular_files_are_refused_unread(tmp_path):
    big = tmp_path / "big.toml"
    big.write_text("# " + "x" * design.MAX_FILE_BYTES)
    with pytest.raises(ConfigError, match="at most"):
        design.load(str(big))
    with pytest.raises(ConfigError, match="not a regular file"):
        design.load(str(tmp_path))
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    with pytest.raises(ConfigError, match="not a regular file"):  # opened without blocking, never read
        design.load(str(fifo))
    link = tmp_path / "link.toml"
    link.symlink_to(write(tmp_path, "seeds = 1\n", "real.toml"))
    with pytest.raises(ConfigError, match="cannot read"):
        design.load(str(link))
    with pytest.raises(ConfigError, match="cannot read"):
        design.load(str(tmp_path / "missing.toml"))


def test_base_from_a_match_configuration_file(tmp_path):
    write(tmp_path, 'home = "AS"\n[rules]\nsetpiece_distance = 2.75\n', "match.toml")
    exp = design.load(write(tmp_path, 'base = "match.toml"\n'))
    assert exp.base.home == "advance-static" and exp.base.rules.setpiece_distance == 2.75
    write(tmp_path, "[rules]\nno_such = 1\n", "bad.toml")
    with pytest.raises(ConfigError, match="rules.no_such"):
        design.load(write(tmp_path, 'base = "bad.toml"\n'))


def test_random_and_latin_hypercube_are_seeded(tmp_path):
    text = BASE + (
        '[design]\nkind = "{kind}"\nsamples = 8\nseed = 7\n[factors]\n'
        '"rules.setpiece_distance" = {{uniform = [2.0, 4.0]}}\n"timing.perception_latency" = {{int = [0, 7]}}\n'
        'away = ["AS", "BD"]\n'
    )
    for kind in ("random", "lhs"):
        one = design.load(write(tmp_path, text.format(kind=kind))).cells
        assert one == design.load(write(tmp_path, text.format(kind=kind))).cells  # the same seed, the same cells
        assert len(one) == 8
        assert all(2.0 <= c["rules.setpiece_distance"] <= 4.0 for c in one)
    lhs = design.load(write(tmp_path, text.format(kind="lhs"))).cells
    # A Latin hypercube puts exactly one sample in each of the 8 strata of every factor.
    assert sorted(int((c["rules.setpiece_distance"] - 2.0) / 2.0 * 8) for c in lhs) == list(range(8))
    assert sorted(c["timing.perception_latency"] for c in lhs) == list(range(8))
    assert sorted(c["away"] for c in lhs) == ["AS"] * 4 + ["BD"] * 4
    other = design.load(write(tmp_path, text.format(kind="lhs").replace("seed = 7", "seed = 8"))).cells
    assert other != lhs


def test_opponents_each_cell_against_the_others(tmp_path):
    exp = design.load(
        write(tmp_path, 'seeds = 2\nopponents = ["AD", "AS", "BS"]\n' + BASE + '[factors]\nhome = ["AD", "BS"]\n')
    )
    first = {m["opponent"] for m in exp.matches() if m["cell"] == 0}
    assert first == {"advance-static", "basic-static"}  # AD's own strategy is not its opponent
    assert len(exp.matches()) == 2 * 2 * 2 * 2
