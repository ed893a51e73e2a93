"""The wall-clock bounds of a match a user may set in `[timing]`: the liveliness lease and the
launcher's grace for summaries. Defaults as documented; bad values one line; each reaches its user."""

from __future__ import annotations

import dataclasses

import pytest

from arena.config import ConfigError, MatchConfig, TimingParams
from arena.match import run as run_module
from arena.match.run import Job, start
from arena.match.supervise import supervision_deadline
from arena.runtime import matchfile
from arena.runtime.session import NetConfig


def test_the_defaults_are_a_6_s_lease_and_6_and_10_s_of_grace():
    t = TimingParams()
    assert (t.lease, t.summary_grace, t.finish_grace) == (6.0, 6.0, 10.0)
    assert NetConfig().zenoh_config().get_json("transport/link/tx/lease") == "6000"


@pytest.mark.parametrize(
    ("timing", "message"),
    [
        ({"lease": 0.1}, "timing.lease must be 0.5 to 600 s, got 0.1"),
        ({"lease": float("nan")}, "timing.lease must be 0.5 to 600 s"),
        ({"lease": 1e9}, "timing.lease must be 0.5 to 600 s"),
        ({"summary_grace": 0.0}, "timing.summary_grace must be a finite number of seconds > 0, got 0.0"),
        ({"finish_grace": float("inf")}, "timing.finish_grace must be a finite number of seconds > 0"),
        ({"finish_grace": -1.0}, "timing.finish_grace must be a finite number of seconds > 0"),
    ],
)
def test_a_bound_out_of_range_is_refused_naming_it(timing, message):
    with pytest.raises(ConfigError, match=message.replace(".", r"\.")):
        MatchConfig.from_dict({"timing": timing})


def test_a_config_file_sets_them(tmp_path):
    path = tmp_path / "quick.toml"
    path.write_text("[timing]\nlease = 2.5\nsummary_grace = 1.0\nfinish_grace = 2.0\n")
    t = matchfile.load(str(path)).timing
    assert (t.lease, t.summary_grace, t.finish_grace) == (2.5, 1.0, 2.0)
    assert NetConfig(lease=t.lease).zenoh_config().get_json("transport/link/tx/lease") == "2500"


def test_the_launchers_deadline_counts_both_graces():
    cfg = MatchConfig(half_time=10.0)
    short = cfg.replace(timing=dataclasses.replace(cfg.timing, summary_grace=1.0, finish_grace=2.0))
    assert supervision_deadline(cfg) - supervision_deadline(short) == pytest.approx(5.0 + 8.0)


def test_a_process_that_reads_the_configuration_first_opens_its_session_with_its_lease(tmp_path, monkeypatch):
    path = tmp_path / "config.json"
    cfg = MatchConfig()
    path.write_text(cfg.replace(timing=dataclasses.replace(cfg.timing, lease=2.0)).to_json())
    seen = []
    monkeypatch.setattr(run_module, "configure_logging", lambda *args, **kwargs: None)
    monkeypatch.setattr(run_module, "main_guarded", lambda fn, pid, match, net, *rest: seen.append(net) or 0)
    assert start(Job(kind="robot", match="m", team="a", robot=1, connect=("tcp/127.0.0.1:1",), config=str(path))) == 0
    # Started by hand, it learns the configuration from the engine over a session already open.
    assert start(Job(kind="robot", match="m", team="a", robot=1, connect=("tcp/127.0.0.1:1",))) == 0
    assert [net.lease for net in seen] == [2.0, 6.0]
