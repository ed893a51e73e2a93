"""Fixtures for integration tests."""

from __future__ import annotations

import os
import signal
import subprocess

import pytest

from tests.integration.helpers import descendants


@pytest.fixture
def reap():
    """Kill whatever a test started, even if it fails half-way."""
    procs: list[subprocess.Popen] = []
    yield procs
    for p in procs:
        if p.poll() is None:
            for d in descendants(p.pid):
                try:
                    os.kill(d, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            p.kill()
        p.communicate()
