"""`arena review --html`: a real headless Chromium opens the replay page of a recorded match."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from tests.integration.helpers import ARENA, arena_json, system_program

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--enable-logging=stderr",
    "--v=0",
]


def chromium() -> str:
    return system_program("chromium", "chromium-browser", install="apt-get install -y chromium")


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("page")
    mcap, html = tmp / "match.mcap", tmp / "replay.html"
    result = arena_json(
        "match", "--home", "AD", "--away", "BS", "--half-time", "15", "--seed", "7", "--record", str(mcap)
    )
    r = subprocess.run([*ARENA, "review", str(mcap), "--html", str(html)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return tmp, html, result


def open_in_chromium(tmp: Path, url: str, *extra: str) -> subprocess.CompletedProcess:
    profile = tmp / f"profile-{len(list(tmp.iterdir()))}"
    return subprocess.run(
        [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *extra, url],
        capture_output=True,
        text=True,
        timeout=120,
    )


def body_attributes(dom: str) -> dict[str, str]:
    body = re.search(r"<body([^>]*)>", dom)
    assert body, dom[:500]
    return dict(re.findall(r'data-([a-z]+)="([^"]*)"', body.group(1)))


def console_errors(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if "CONSOLE" in line or "Uncaught" in line]


def test_the_page_is_one_self_contained_file(page):
    _, html, _ = page
    text = html.read_text()
    assert "<script src" not in text and "<link" not in text and "@import" not in text
    assert not re.search(r"https?://", text), "the page must not reach the network"
    assert html.stat().st_size < 1_000_000


def test_chromium_draws_the_field_and_six_robots_with_no_console_errors(page):
    tmp, html, _ = page
    r = open_in_chromium(tmp, html.as_uri(), "--dump-dom", "--virtual-time-budget=2000")
    assert r.returncode == 0, r.stderr[-2000:]
    attrs = body_attributes(r.stdout)
    assert attrs["field"] == "1" and attrs["robots"] == "6" and attrs["frame"] == "0", attrs
    assert attrs["errors"] == "0", attrs
    assert console_errors(r.stderr) == []
    # the score line of a fresh page is the kickoff's
    assert re.search(r'id="score">advance-dynamic \(a\) +0 : 0 +\(b\) basic-static<', r.stdout)


def test_chromium_plays_the_match_and_a_screenshot_is_taken(page):
    tmp, html, _ = page
    r = open_in_chromium(tmp, html.as_uri() + "#play", "--dump-dom", "--virtual-time-budget=3000")
    attrs = body_attributes(r.stdout)
    assert 10 <= int(attrs["frame"]) <= 40 and attrs["robots"] == "6" and attrs["errors"] == "0", attrs
    assert console_errors(r.stderr) == []
    r = open_in_chromium(tmp, html.as_uri() + "#t=12", "--dump-dom", "--virtual-time-budget=1000")
    attrs = body_attributes(r.stdout)
    assert attrs["frame"] == "120" and attrs["robots"] == "6", attrs  # 10 frames a second
    shot = tmp / "replay.png"
    r = open_in_chromium(tmp, html.as_uri(), f"--screenshot={shot}", "--window-size=1100,900")
    assert r.returncode == 0 and shot.stat().st_size > 10_000
