"""Imports never point up. Each package may import only packages of a lower rank
(and itself); the ranks are the package map of docs/architecture.md. Inside
tools/, the sub-packages are ranked the same way, and the command line
(arena.cli, arena.commands) is above everything: nothing else imports it."""

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
    "refbox": 3,  # the RefBox protocol's sockets and threads, over the pure rules
    "processes": 4,
    "tools": 5,
    "match": 5,  # arena.match, the one way to play a match: inside rank 5, just above tools.launch (MATCH)
    "scenarios": 6,  # the scenario file, runner, pytest plugin and library: may use tools
    "learn": 7,  # arena.learn: the learning environments, over the in-process engine; resets from scenarios
    "arena": 8,  # arena/cli.py, arena/commands/ and arena/__main__.py: the command line, above everything
}
# arena's own modules: the command line. Nothing outside arena/ may import them.
COMMAND_LINE = {"cli", "commands", "__main__"}
# Inside tools/, bottom-up: a module of tools/ itself (console.py), then the sub-packages by concern.
TOOLS_RANK = {"": 0, "launch": 1, "review": 3, "experiments": 4}
# arena.match wraps tools.launch's engines; tools.review and tools.experiments play matches through it.
MATCH = (RANK["match"], 2)


def unit(name: str) -> tuple[str, str] | None:
    """The (package, tools sub-package or "") that the module `arena.x.y...` belongs to; None for
    what the layering does not rank (arena's root package itself, e.g. `arena.__version__`)."""
    parts = name.split(".")
    if parts[0] != "arena" or len(parts) < 2:
        return None
    if parts[1] in COMMAND_LINE:
        return ("arena", "")
    if parts[1] not in RANK:
        return None
    sub = parts[2] if parts[1] == "tools" and len(parts) > 2 and parts[2] in TOOLS_RANK else ""
    return (parts[1], sub)


def rank(u: tuple[str, str]) -> tuple[int, int]:
    return MATCH if u[0] == "match" else (RANK[u[0]], TOOLS_RANK[u[1]])


def imported_units(path: Path) -> set[tuple[str, str]]:
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
    """Every import in the tree at `root` that points to its own rank or above (its own unit aside)."""
    bad = []
    for pkg in RANK:
        for path in sorted((root / pkg).rglob("*.py")):
            rel = path.relative_to(root / pkg).parts
            own = (pkg, rel[0] if pkg == "tools" and len(rel) > 1 and rel[0] in TOOLS_RANK else "")
            for dep in sorted(imported_units(path) - {own}):
                if rank(dep) >= rank(own):
                    name = "the command line" if dep[0] == "arena" else ".".join(("arena", *filter(None, dep)))
                    bad.append(f"{path.relative_to(root)} imports {name} (rank {rank(dep)} >= {rank(own)})")
    return bad


def test_every_package_is_ranked():
    pkgs = {p.parent.name for p in ROOT.glob("*/__init__.py")} - {"tests", "examples"}
    assert pkgs <= set(RANK), f"unranked packages: {sorted(pkgs - set(RANK))}"
    subs = {p.parent.name for p in (ROOT / "tools").glob("*/__init__.py")}
    assert subs <= set(TOOLS_RANK), f"unranked tools sub-packages: {sorted(subs - set(TOOLS_RANK))}"


def test_imports_never_point_up():
    bad = upward_imports(ROOT)
    assert not bad, "\n".join(bad)


def test_the_check_fails_on_a_planted_upward_import(tmp_path):
    planted = {
        "tools/launch/forked.py": "def go():\n    from arena.cli import main\n",
        "runtime/plugin.py": "from arena import commands\n",
        "tools/launch/table.py": "from arena.tools.experiments import tournament\n",
        "tools/experiments/scen.py": "import arena.commands.match\n",
        "processes/up.py": "from arena.tools.launch.run import start\n",
        "learn/cmd.py": "from arena.cli import parser\n",
        "tools/launch/seam.py": "from arena.match import play\n",
        "match/report.py": "from arena.tools.review import report\n",
    }
    fine = {
        "tools/review/ok.py": "from arena.tools.launch import launcher\nfrom arena import __version__\n",
        "arena/commands/ok.py": "from arena.tools.experiments import tournament\nfrom arena.commands import _common\n",
        "tools/launch/same.py": "from arena.tools.launch import run\nfrom arena.runtime.config import MatchConfig\n",
        "match/ok.py": "from arena.tools.launch import inprocess\nfrom arena.match import engines\n",
        "tools/experiments/ok.py": "from arena.match import play\n",
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
