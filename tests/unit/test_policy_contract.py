"""schemas/README.md's section on playing a policy holds to the code: the observation's parts, sizes and
bounds (arena.strategies.learned.obs_fields) and the discrete moves (DISCRETE)."""

from __future__ import annotations

import re

from arena.schemas.policy_contract import POLICY
from arena.strategies.learned import DISCRETE, obs_fields


def _table() -> dict[str, tuple[str, str]]:
    rows = {}
    for line in POLICY.splitlines():
        cells = [c.strip() for c in line.strip("|").split("|")]
        if line.startswith("| ") and len(cells) == 4 and cells[0] not in ("part",):
            rows[cells[0]] = (cells[1], cells[2])
    return rows


def test_the_observation_table_has_the_codes_parts_sizes_and_bounds():
    table = _table()
    for r in range(1, 7):
        fields = obs_fields(r)
        assert [name for name, *_ in fields] == list(table)
        assert sum(n for _, n, *_ in fields) == 45 + 8 * r  # "D = 45 + 8r"
        for name, n, low, high, _ in fields:
            size, bounds = table[name]
            assert eval(size.replace("r", str(r))) == n, name  # "4 * (2 * r - 1)" for robots
            lo, hi = (float(x) for x in re.findall(r"-?\d+", bounds))
            assert (lo, hi) == (low, high), name


def test_the_discrete_moves_are_the_codes():
    for i, (name, (vx, vy, om, kick)) in enumerate(DISCRETE):
        shown = f"{i} {name} ({vx:g}, {vy:g}, {om:g}, {kick:g})"
        assert shown in " ".join(POLICY.split()), shown
