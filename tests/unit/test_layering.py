"""Imports never point up. Each package may import only packages of a lower rank
(and itself); the ranks are the package map of docs/architecture.md, and the
command line (arena.cli, arena.commands) is above everything: nothing else imports it."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

RANK = {
    "schemas": 0,
    "config": 1,  # the match configuration, what every process plays by: over the wire's vocabulary only
    "navigation": 1,
    "runtime": 2,
    "sim": 3,
    "rules": 3,
    "recording": 3,
    "strategies": 4,
    "refbox": 4,  # the RefBox protocol's sockets and threads, over the pure rules
    "processes": 5,
    "match": 6,  # the one way to play a match, both engines (the launcher, the in-process engine)
    "review": 7,  # looking back at a match: review, replay, the text report, the console
    "experiments": 8,  # many matches or measurements: tournaments, cluster, facts, benchmarks
    "scenarios": 9,  # the scenario file, runner, pytest plugin and library: may use experiments' bench
    "learn": 10,  # arena.learn: the learning environments, over the in-process engine; resets from scenarios
    "arena": 11,  # arena/cli.py, arena/commands/ and arena/__main__.py: the command line, above everything
}
# arena's own modules: the command line. Nothing outside arena/ may import them.
COMMAND_LINE = {"cli", "commands", "__main__"}


def unit(name: str) -> str | None:
    """The package that the module `arena.x.y...` belongs to; None for what the layering does not
    rank (arena's root package itself, e.g. `arena.__version__`)."""
    parts = name.split(".")
    if parts[0] != "arena" or len(parts) < 2:
        return None
    if parts[1] in COMMAND_LINE:
        return "arena"
    return parts[1] if parts[1] in RANK else None


def imported_units(path: Path) -> set[str]:
    """Every ranked unit this file imports, at module level or inside functions."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        out |= {u for u in map(unit, names) if u is not None}
    return out


def upward_imports(root: Path) -> list[str]:
    """Every import in the tree at `root` that points to its own rank or above (its own package aside)."""
    bad = []
    for pkg in RANK:
        for path in sorted((root / pkg).rglob("*.py")):
            for dep in sorted(imported_units(path) - {pkg}):
                if RANK[dep] >= RANK[pkg]:
                    name = "the command line" if dep == "arena" else f"arena.{dep}"
                    bad.append(f"{path.relative_to(root)} imports {name} (rank {RANK[dep]} >= {RANK[pkg]})")
    return bad


def test_every_package_is_ranked():
    pkgs = {p.parent.name for p in ROOT.glob("*/__init__.py")} - {"tests", "examples"}
    assert pkgs <= set(RANK), f"unranked packages: {sorted(pkgs - set(RANK))}"


def test_every_room_says_what_it_holds_and_what_it_may_import():
    """Each package's __init__ opens with what lives there and names what it may import."""
    quiet = []
    for pkg in RANK:
        doc = ast.get_docstring(ast.parse((ROOT / pkg / "__init__.py").read_text())) or ""
        if len(doc.split()) < 12 or "import" not in doc.lower():
            quiet.append(pkg)
    assert not quiet, f"say what lives there and what it may import: {quiet}"


def test_imports_never_point_up():
    bad = upward_imports(ROOT)
    assert not bad, "\n".join(bad)


def test_the_check_fails_on_a_planted_upward_import(tmp_path):
    planted = {
        "match/forked.py": "def go():\n    from arena.cli import main\n",
        "runtime/plugin.py": "from arena import commands\n",
        "match/table.py": "from arena.experiments import tournament\n",
        "experiments/scen.py": "import arena.commands.match\n",
        "processes/up.py": "from arena.match.run import start\n",
        "learn/cmd.py": "from arena.cli import parser\n",
        "processes/seam.py": "from arena.match import play\n",
        "match/report.py": "from arena.review import report\n",
        "review/bench.py": "from arena.experiments.bench import print_metrics\n",
        "sim/steps.py": "from arena.rules import setpieces\n",  # the same rank
    }
    fine = {
        "review/ok.py": "from arena.match import launcher\nfrom arena import __version__\n",
        "arena/commands/ok.py": "from arena.experiments import tournament\nfrom arena.commands import _common\n",
        "match/same.py": "from arena.match import run\nfrom arena.config import MatchConfig\n",
        "match/ok.py": "from arena.processes import node_class\nfrom arena.match import engines\n",
        "experiments/ok.py": "from arena.match import play\nfrom arena.review.console import console\n",
        "sim/director.py": "from arena.sim.physics import Physics\nfrom arena.schemas import messages\n",
    }
    for rel, text in {**planted, **fine}.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    bad = upward_imports(tmp_path)
    assert sorted(line.split(" imports ")[0] for line in bad) == sorted(planted), bad


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


def test_rules_stay_pure():
    """rules/ is the laws of the game and the RefBox wire as pure functions: no socket, thread or clock
    (those are arena.refbox, processes and runtime)."""
    impure = {"socket", "selectors", "threading", "queue", "time", "subprocess", "asyncio"}
    bad = []
    for path in sorted((ROOT / "rules").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            bad += [f"{path.relative_to(ROOT)} imports {n}" for n in names if n.split(".")[0] in impure]
    assert not bad, "\n".join(bad)
