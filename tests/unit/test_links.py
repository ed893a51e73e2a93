"""Link emulation: presets, overrides, Gilbert-Elliott statistics, seeding."""

from __future__ import annotations

import random
import statistics

import pytest

from arena.config import ConfigError
from arena.runtime.links import PRESETS, LinkEmulator, LinkModel, parse_override, resolve


def run(model: LinkModel, n: int, seed: int = 1) -> LinkEmulator:
    e = LinkEmulator(model, random.Random(seed))
    for _ in range(n):
        e.decide()
    return e


def test_ideal_drops_and_delays_nothing():
    e = run(PRESETS["ideal"]["wifi"], 10_000)
    assert e.dropped == 0 and e.frames == 10_000


@pytest.mark.parametrize("preset", ["lan", "wifi", "congested-wifi"])
def test_measured_loss_matches_stationary_rate(preset):
    model = PRESETS[preset]["wifi"]
    e = run(model, 200_000)
    expected = model.stationary_loss()
    assert e.dropped / e.frames == pytest.approx(expected, rel=0.15, abs=2e-4)


def test_loss_is_bursty_in_the_bad_state():
    # Mean burst length of consecutive losses is ~1/p_bg when loss_bad = 1.
    model = LinkModel(p_gb=0.05, p_bg=0.25, loss_good=0.0, loss_bad=1.0)
    e = LinkEmulator(model, random.Random(3))
    bursts, run_len = [], 0
    for _ in range(100_000):
        if e.decide() is None:
            run_len += 1
        elif run_len:
            bursts.append(run_len)
            run_len = 0
    assert statistics.mean(bursts) == pytest.approx(1 / 0.25, rel=0.1)


def test_delay_is_latency_plus_exponential_jitter():
    model = LinkModel(latency_ms=15.0, jitter_ms=25.0)
    e = run(model, 50_000)
    assert min(e.delays_ms) >= 15.0
    assert statistics.mean(e.delays_ms) == pytest.approx(40.0, rel=0.03)


def test_same_seed_same_decisions_other_seed_other_decisions():
    model = PRESETS["congested-wifi"]["wifi"]
    a = LinkEmulator(model, random.Random(7))
    b = LinkEmulator(model, random.Random(7))
    c = LinkEmulator(model, random.Random(8))
    da = [a.decide() for _ in range(2000)]
    assert da == [b.decide() for _ in range(2000)]
    assert da != [c.decide() for _ in range(2000)]


def test_overrides_apply_per_parameter():
    models = resolve("wifi", {"wifi": {"latency_ms": 30.0}})
    assert models["wifi"].latency_ms == 30.0
    assert models["wifi"].jitter_ms == PRESETS["wifi"]["wifi"].jitter_ms
    assert parse_override("wifi.p_gb=0.02") == ("wifi", "p_gb", 0.02)


@pytest.mark.parametrize(
    ("preset", "overrides", "message"),
    [
        ("bogus", {}, "unknown link preset"),
        ("wifi", {"radio": {"latency_ms": 1}}, "unknown link class"),
        ("wifi", {"wifi": {"speed": 1}}, "unknown link parameter"),
        ("wifi", {"wifi": {"p_gb": 1.5}}, "must be in [0, 1]"),
        ("wifi", {"wifi": {"latency_ms": -1}}, "must be in [0, 10000]"),
    ],
)
def test_bad_link_settings_are_rejected_with_a_reason(preset, overrides, message):
    with pytest.raises(ConfigError, match=message.replace("[", r"\[").replace("]", r"\]")):
        resolve(preset, overrides)


def test_bad_override_syntax():
    with pytest.raises(ConfigError, match="CLASS.PARAM=VALUE"):
        parse_override("wifi-latency=3")
