"""The OS processes of a match the launcher starts: exec'd (`spawn`) or forked
(match/forkstart.py), each a `Child` with its log; stopped together."""

from __future__ import annotations

import contextlib
import ctypes
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from arena.config import ProcessId
from arena.match.result import JoinError, MatchError
from arena.match.run import Job

__all__ = ["Child", "JoinError", "MatchError", "run_argv", "spawn", "stop_all", "stopped_on_error"]

_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """Runs in the child before exec: SIGKILL it if the launcher dies."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except OSError:
        pass


@dataclass
class Child:
    name: str
    pid: ProcessId
    popen: subprocess.Popen
    log_path: Path

    def tail(self, lines: int = 8) -> str:
        try:
            text = self.log_path.read_text(errors="replace").rstrip().splitlines()
        except OSError:
            return ""
        return "\n".join("    " + line for line in text[-lines:])


def run_argv(job: Job) -> list[str]:
    """`python -m arena run ...`: the command that runs `job` in a fresh interpreter."""
    return [sys.executable, "-m", "arena", *job.argv()]


def spawn(name: str, pid: ProcessId, argv: list[str], log_dir: Path, env: dict[str, str] | None = None) -> Child:
    log_path = log_dir / (name.replace("/", "_") + ".log")
    fh = open(log_path, "wb")
    try:
        popen = subprocess.Popen(
            argv,
            stdin=subprocess.DEVNULL,
            stdout=fh,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # Ctrl-C reaches the launcher only; it stops the group
            preexec_fn=_die_with_parent,
            env=env,
        )
    finally:
        fh.close()
    return Child(name, pid, popen, log_path)


def stop_all(children: list[Child], grace: float = 3.0) -> None:
    """SIGTERM every child still running, SIGKILL any still there `grace` seconds later.

    Each gets SIGCONT after its SIGTERM, as a service manager does: a stopped child (SIGSTOP,
    the hung process of a fault) then ends on its SIGTERM at once instead of at the SIGKILL."""
    for c in children:
        if c.popen.poll() is None:
            c.popen.send_signal(signal.SIGTERM)
            c.popen.send_signal(signal.SIGCONT)
    deadline = time.monotonic() + grace
    for c in children:
        left = max(0.0, deadline - time.monotonic())
        try:
            c.popen.wait(timeout=left)
        except subprocess.TimeoutExpired:
            c.popen.kill()
            c.popen.wait()


@contextlib.contextmanager
def stopped_on_error(children: list[Child]) -> Iterator[None]:
    """`stop_all` if the block raises (Ctrl-C, SIGTERM, a failure), before what encloses it closes.

    Inside the router's `with`: the children end while the router still serves their links, as
    at a match's normal end. A zenoh router closed under ten live links could panic in its
    receive threads, and their messages came after the launcher's last line."""
    try:
        yield
    except BaseException:
        stop_all(children)
        raise
