"""Every refactor proves itself by unchanged digests: 20 fixed matches, per process.

The reference is tests/golden/digests.json, written by tests/golden/make_digests.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.golden.make_digests import CONFIGS, digests

GOLDEN = Path(__file__).resolve().parents[1] / "golden"

REFERENCE = json.loads((GOLDEN / "digests.json").read_text())


def test_the_reference_covers_the_configurations():
    assert [r["config"] for r in REFERENCE] == CONFIGS
    assert len(CONFIGS) == 20


@pytest.mark.parametrize("i", range(len(REFERENCE)), ids=lambda i: f"cfg{i}")
def test_digests_unchanged(i):
    ref = REFERENCE[i]
    got = digests(ref["config"])
    changed = sorted(p for p in ref["digests"] if got.get(p) != ref["digests"][p])
    assert not changed and got.keys() == ref["digests"].keys(), f"{ref['config']}: changed {changed}"
