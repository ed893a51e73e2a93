"""`stop_all`, the end of every match the launcher started: SIGTERM, then SIGKILL after a grace."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from arena.config import ProcessId
from arena.match.children import Child, stop_all, stopped_on_error


def test_a_stopped_child_ends_on_its_sigterm_at_once_not_at_the_sigkill(tmp_path):
    """A SIGSTOPped child (the hung process of a fault) kept its SIGTERM pending, so the launcher
    waited the whole grace and killed it; it now gets SIGCONT too, as from a service manager."""
    popen = subprocess.Popen([sys.executable, "-c", "import time; print('up', flush=True); time.sleep(60)"],
                             stdout=subprocess.PIPE, text=True)  # fmt: skip
    try:
        assert popen.stdout.readline() == "up\n"
        os.kill(popen.pid, signal.SIGSTOP)
        t0 = time.monotonic()
        stop_all([Child("robot/a/1", ProcessId("robot", "a", 1), popen, tmp_path / "log")], grace=30.0)
        assert time.monotonic() - t0 < 10.0, "it waited for the grace to end"
        assert popen.returncode == -signal.SIGTERM, "ended by its SIGTERM, not killed"
    finally:
        popen.kill()
        popen.communicate()


def test_the_children_are_stopped_before_what_encloses_the_block_closes(tmp_path):
    """The launcher's router `with`: on Ctrl-C or SIGTERM the children end while the router still
    serves their links; a zenoh router closed under live links could panic after the last line."""
    popen = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    seen_at_close: list[int | None] = []

    class Router:
        def __enter__(self):
            return self

        def __exit__(self, *exc):
            seen_at_close.append(popen.poll())

    try:
        children = [Child("robot/a/1", ProcessId("robot", "a", 1), popen, tmp_path / "log")]
        try:
            with Router(), stopped_on_error(children):
                raise KeyboardInterrupt
        except KeyboardInterrupt:
            pass
        assert seen_at_close == [-signal.SIGTERM], "the child was still running when the router closed"
    finally:
        popen.kill()
        popen.wait()
