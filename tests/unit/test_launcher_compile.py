"""`compile_sources`: arena's bytecode is written once per match, not compiled by all eleven processes."""

from __future__ import annotations

import compileall
import importlib.util
import os
import sys

from arena.match import launcher
from arena.runtime import seeds


def test_writes_arenas_bytecode_when_the_interpreters_would_not(monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    pyc = importlib.util.cache_from_source(seeds.__file__)
    if os.path.exists(pyc):
        os.remove(pyc)
    launcher.compile_sources()
    assert os.path.exists(pyc)
    assert os.path.getmtime(pyc) >= os.path.getmtime(seeds.__file__)


def test_does_nothing_when_the_interpreters_write_their_own(monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", False)

    def fail(*args, **kwargs):
        raise AssertionError("compile_dir called")

    monkeypatch.setattr(compileall, "compile_dir", fail)
    launcher.compile_sources()


def test_a_read_only_install_is_not_an_error(monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", True)

    def read_only(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(compileall, "compile_dir", read_only)
    launcher.compile_sources()


def test_every_package_of_the_distribution_is_compiled(monkeypatch):
    """Each package pyproject.toml ships, subpackages included (arena.sim.physics was
    missed once: the rules, the physics and the strategies compiled in every launch)."""
    import tomllib
    from pathlib import Path

    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    pyproject = tomllib.loads((Path(__file__).parents[2] / "pyproject.toml").read_text())
    packages = pyproject["tool"]["setuptools"]["packages"]
    pycs = []
    for name in packages:
        spec = importlib.util.find_spec(name)
        assert spec is not None and spec.submodule_search_locations, name
        for source in sorted(Path(next(iter(spec.submodule_search_locations))).glob("*.py")):
            pyc = importlib.util.cache_from_source(str(source))
            if os.path.exists(pyc):
                os.remove(pyc)
            pycs.append(pyc)
    launcher.compile_sources()
    missing = [p for p in pycs if not os.path.exists(p)]
    assert not missing, missing
