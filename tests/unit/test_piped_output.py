"""Piped output never wraps: rich wrapped at 80 columns when stdout was not a terminal
(`...engine \\nprocesses`, `digest \\nb14fc08017586ca8`), which broke grep and logs."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_every_printer_uses_the_console_that_does_not_wrap_when_piped():
    made_here = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in {"tests", ".venv", "examples", "build"} or str(rel) == "review/console.py":
            continue
        if re.search(r"\bConsole\(", path.read_text()):
            made_here.append(str(rel))
    assert made_here == [], "make consoles with arena.review.console.console(), which never wraps piped output"


def test_a_piped_match_report_keeps_every_line_whole():
    r = subprocess.run(
        [sys.executable, "-m", "arena", "match", "--home", "BS", "--away", "AD", "--half-time", "1", "--seed", "7"],
        capture_output=True,
        text=True,
        timeout=120,
        env={k: v for k, v in os.environ.items() if k != "COLUMNS"},
    )
    assert r.returncode == 0, r.stderr
    first, second = r.stdout.splitlines()[:2]
    assert first.endswith("engine processes"), first
    assert re.search(r"digest [0-9a-f]{16}$", second), second


def test_the_console_is_wide_when_piped_and_the_terminals_width_on_a_terminal(monkeypatch):
    from arena.review import console

    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.setattr(sys.stdout, "isatty", lambda: False, raising=False)
    assert console.console().width == console.PIPED_WIDTH
    monkeypatch.setenv("COLUMNS", "100")
    assert console.console().width == 100, "a COLUMNS the user set wins"
