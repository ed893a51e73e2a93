"""Imports never point up. Each package may import only packages of a lower rank
(and itself); the ranks are the package map of docs/architecture.md."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

RANK = {
    "schemas": 0,
    "runtime": 1,
    "navigation": 1,
    "sim": 2,
    "rules": 2,
    "recording": 2,
    "strategies": 3,
    "processes": 4,
    "tools": 5,
    "scenarios": 6,  # the scenario file, runner, pytest plugin and library: may use tools
    "learn": 7,  # arena.learn: the learning environments, over the in-process engine; resets from scenarios
    "arena": 8,  # arena/cli.py and arena/__main__.py
}


def imported_packages(path: Path) -> set[str]:
    """Every `arena.<pkg>` this file imports, at module level or inside functions."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        for name in names:
            parts = name.split(".")
            if parts[0] == "arena" and len(parts) > 1 and parts[1] in RANK:
                out.add(parts[1])
    return out


def test_every_package_is_ranked():
    pkgs = {p.parent.name for p in ROOT.glob("*/__init__.py")} - {"tests", "examples"}
    assert pkgs <= set(RANK), f"unranked packages: {sorted(pkgs - set(RANK))}"


def test_imports_never_point_up():
    bad = []
    for pkg, rank in RANK.items():
        for path in sorted((ROOT / pkg).rglob("*.py")):
            for dep in imported_packages(path) - {pkg}:
                if RANK[dep] >= rank:
                    bad.append(f"{path.relative_to(ROOT)} imports arena.{dep} (rank {RANK[dep]} >= {rank})")
    assert not bad, "\n".join(bad)


def test_every_package_is_installed():
    """pyproject.toml lists every package of the tree, so a non-editable install has them all."""
    import tomllib

    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = set()
    for pkg in RANK:
        for init in (ROOT / pkg).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT / pkg).parts
            found.add(".".join(("arena",) if pkg == "arena" else ("arena", pkg, *rel)))
    assert found <= listed, f"not in pyproject.toml packages: {sorted(found - listed)}"
