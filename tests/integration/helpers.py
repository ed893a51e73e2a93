"""Helpers for integration tests: real `arena` processes over real zenoh."""

from __future__ import annotations

import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

ARENA = [sys.executable, "-m", "arena"]


def arena_in_process(argv: list[str], capfd) -> subprocess.CompletedProcess:
    """`arena ARGV` through `python -m arena`'s entry point, arena.cli.main, in this process: what a
    process would have said (stdout, stderr: fd-level, so native code's lines count too) and its exit code.
    For a test of a command's output; what is about the process (its exit, a traceback) needs a real one.

    What a command sets for its whole process is put back afterwards: the SIGTERM handler
    (arena/cli.py), the root logger (`arena run`), ZENOH_RUNTIME (runtime/session.py)."""
    from arena import cli

    root = logging.getLogger()
    handlers, level, sigterm, env = root.handlers[:], root.level, signal.getsignal(signal.SIGTERM), dict(os.environ)
    capfd.readouterr()
    try:
        code = cli.main(argv)
    except SystemExit as exc:  # as `raise SystemExit(main())` in arena/__main__.py would end
        code = exc.code
    finally:
        root.handlers[:], root.level = handlers, level
        signal.signal(signal.SIGTERM, sigterm)
        os.environ.clear()
        os.environ.update(env)
    out, err = capfd.readouterr()
    return subprocess.CompletedProcess(["arena", *argv], code, out, err)


def system_program(*names: str, install: str) -> str:
    """The path of the first of `names` on PATH.

    An optional system program (README's "Tests" names them) that is absent skips the test with the command
    that installs it, so a fresh machine passes; with CI set (`.ci/run` installs them) absence fails instead.
    """
    for name in names:
        if exe := shutil.which(name):
            return exe
    reason = f"{names[0]} is not installed: {install} (.ci/run installs it)"
    if os.environ.get("CI"):
        pytest.fail(f"{reason}; CI is set, so this test must run", pytrace=False)
    pytest.skip(reason)


def arena_json(*args: str, timeout: float = 240.0, env: dict | None = None) -> dict:
    """Run `arena <args> --json`, require exit 0, return the parsed JSON."""
    r = subprocess.run([*ARENA, *args, "--json"], capture_output=True, text=True, timeout=timeout, env=env)
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stderr[-3000:]}"
    return json.loads(r.stdout)


def free_ports(n: int = 1) -> list[int]:
    """`n` distinct free ports on 127.0.0.1: all are held at once, so no two of them are the same."""
    socks = [socket.socket() for _ in range(n)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in socks]
    finally:
        for s in socks:
            s.close()


def free_port() -> int:
    return free_ports(1)[0]


def spawn(*args: str, **kw) -> subprocess.Popen:
    return subprocess.Popen([*ARENA, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def descendants(pid: int) -> set[int]:
    """Every live process below `pid` (from /proc)."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        ppid = int(stat[stat.rindex(")") + 2 :].split()[1])
        children.setdefault(ppid, []).append(int(entry.name))
    out, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.add(c)
            todo.append(c)
    return out


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


def cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


def wait_for(predicate, timeout: float, what: str, interval: float = 0.05):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(interval)
    raise AssertionError(f"timed out after {timeout:g} s waiting for {what}")


def wait_until_playing(endpoint: str, match: str, timeout: float = 60.0) -> None:
    """Block until the match's referee has sent a frame (the start barrier is behind us)."""
    import zenoh

    from arena.runtime.session import NetConfig, open_session

    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        referee = session.declare_subscriber(f"arena/{match}/referee", zenoh.handlers.FifoChannel(1000))
        wait_for(lambda: referee.try_recv(), timeout, "the match to start")
        referee.undeclare()


def wait_until_joined(endpoint: str, match: str, process: str, timeout: float = 60.0) -> None:
    """Block until `process` (e.g. robot/a/1) holds its liveliness token in the match."""
    import zenoh

    from arena.runtime.session import NetConfig, open_session
    from arena.schemas.keys import Keys

    with open_session(NetConfig(mode="client", connect=(endpoint,))) as session:
        token = session.liveliness().declare_subscriber(
            Keys(match).alive(process), zenoh.handlers.FifoChannel(16), history=True
        )
        wait_for(lambda: token.try_recv(), timeout, f"{process} to join")
        token.undeclare()
