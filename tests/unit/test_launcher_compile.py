"""`compile_sources`: arena's bytecode is written once per match, not compiled by all eleven processes."""

from __future__ import annotations

import compileall
import importlib.util
import os
import sys

from arena.runtime import seeds
from arena.tools import launcher


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
