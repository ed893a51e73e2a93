"""A test needing an absent system program skips on a fresh machine, naming the install command, and fails in CI."""

from __future__ import annotations

import pytest

from tests.integration.helpers import system_program


def test_an_absent_program_skips_with_the_install_command(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match=r"chromium is not installed: apt-get install -y chromium"):
        system_program("chromium", "chromium-browser", install="apt-get install -y chromium")


def test_an_absent_program_fails_when_ci_is_set(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match=r"CI is set, so this test must run"):
        system_program("chromium", install="apt-get install -y chromium")


def test_a_present_program_is_found_by_any_of_its_names(monkeypatch, tmp_path):
    exe = tmp_path / "chromium-browser"
    exe.write_text("#!/bin/sh\n")
    exe.chmod(0o755)
    monkeypatch.setenv("PATH", str(tmp_path))
    assert system_program("chromium", "chromium-browser", install="x") == str(exe)
