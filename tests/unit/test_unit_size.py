"""No unit over ~150 lines without a reason written at its top (issue 13).

A non-test module over 150 lines says why in its docstring, in a paragraph
that begins "Longer than 150 lines because"; a class or function over 150
lines is named in that paragraph. The test lists every offender at once."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIMIT = 150
PHRASE = "Longer than 150 lines because"


def modules() -> list[Path]:
    """Every .py file of the arena packages (top-level folders with an __init__.py), tests and examples aside."""
    pkgs = sorted(p.parent for p in ROOT.glob("*/__init__.py") if p.parent.name not in {"tests", "examples"})
    return [path for pkg in pkgs for path in sorted(pkg.rglob("*.py"))]


def reason(tree: ast.Module) -> str | None:
    """The docstring's paragraph that gives the reason, or None."""
    doc = ast.get_docstring(tree) or ""
    for para in doc.split("\n\n"):
        if PHRASE in para:
            return para
    return None


def long_units(tree: ast.Module) -> list[tuple[str, int]]:
    units = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)
    return [
        (node.name, node.end_lineno - node.lineno + 1)
        for node in ast.walk(tree)
        if isinstance(node, units) and node.end_lineno - node.lineno + 1 > LIMIT
    ]


def test_the_packages_are_found():
    names = {p.relative_to(ROOT).parts[0] for p in modules()}
    assert {"runtime", "processes", "schemas", "tools"} <= names


def test_long_modules_say_why():
    missing = []
    for path in modules():
        text = path.read_text()
        n = len(text.splitlines())
        if n > LIMIT and reason(ast.parse(text, str(path))) is None:
            missing.append(f"{path.relative_to(ROOT)}: {n} lines, no '{PHRASE} ...' in its docstring")
    assert not missing, "\n".join(missing)


def test_long_units_are_named_in_the_reason():
    missing = []
    for path in modules():
        tree = ast.parse(path.read_text(), str(path))
        why = reason(tree) or ""
        for name, n in long_units(tree):
            if f"`{name}`" not in why:
                missing.append(
                    f"{path.relative_to(ROOT)}: `{name}` is {n} lines and its module's reason does not name it"
                )
    assert not missing, "\n".join(missing)


def test_the_check_can_fail():
    long = '"""Short."""\n' + "x = 1\n" * (LIMIT + 1)
    assert reason(ast.parse(long)) is None
    why = f'"""Short.\n\n{PHRASE} `f` is one loop.\n"""\n'
    assert reason(ast.parse(why)) is not None
    body = "def f():\n" + "    x = 1\n" * (LIMIT + 1)
    assert long_units(ast.parse(body)) == [("f", LIMIT + 2)]
