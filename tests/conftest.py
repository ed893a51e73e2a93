"""Suite-wide: tests marked `slow` run only when asked for with ``-m slow``; test modules keep their bytecode."""

from __future__ import annotations

import sys

import pytest


@pytest.hookimpl(wrapper=True)
def pytest_collection(session: pytest.Session):
    """Collect with bytecode writing on, even under PYTHONDONTWRITEBYTECODE.

    Without it pytest rewrites the asserts of every test module and compiles it again on every
    run: ~3 s of the ~5 s of CPU that collecting the suite took. With it the rewritten modules
    are cached in the usual `__pycache__` directories (ignored by git), as arena's own are
    (match/launcher.py, `compile_sources`). The tests themselves run with the setting
    the environment gave.
    """
    wrote = sys.dont_write_bytecode
    sys.dont_write_bytecode = False
    try:
        return (yield)
    finally:
        sys.dont_write_bytecode = wrote


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if "slow" in (config.getoption("-m") or ""):
        return
    skip = pytest.mark.skip(reason="slow: opt-in with -m slow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(autouse=True, scope="session")
def _temp_dirs_inside_pytests_own(tmp_path_factory: pytest.TempPathFactory):
    """Matches that a test makes fail keep their logs in a temp dir; keep those under pytest's own."""
    import os
    import tempfile

    path = str(tmp_path_factory.mktemp("tmp"))
    old_env, old_dir = os.environ.get("TMPDIR"), tempfile.tempdir
    os.environ["TMPDIR"] = path
    tempfile.tempdir = path
    yield
    tempfile.tempdir = old_dir
    if old_env is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = old_env
