"""Start a match's processes by forking one parent that has imported everything.

`arena match` used to start every process as `python -m arena run <kind>`:
eleven interpreters, each importing zenoh, numpy, pymunk and the strategies,
which took about 1.4 s of a match's wall time on a quiet host and ~2.5 s of
its CPU. Here the launcher imports every process kind once (`preload`) and
`os.fork`s one child per process. A child runs the same typed entry as
`arena run <kind> ...` (`arena.match.run.start` with the launcher's
`Job`), so every process, and the per-process one for hardware in the loop,
starts one way; no child parses a command line.

Rules kept:
* No zenoh session exists in the launcher when it forks (a forked session's
  runtime threads would not exist in the child). The launcher forks first,
  then opens the match's router; each child waits on a pipe until the router
  is up (`release`) before it opens its own session. If the launcher dies
  first, the pipe reads end-of-file and the child exits.
* Each child gets its own session (`setsid`, Ctrl-C reaches the launcher
  only), `PR_SET_PDEATHSIG` (it dies with the launcher) and its own log file
  on stdout and stderr, as an exec'd child did.
* The launcher is the real parent: `ForkedProcess` waits for its children
  like `subprocess.Popen` does (`poll`, `wait`, `send_signal`, `kill`).

`ARENA_LAUNCH=exec` keeps the former exec start (for comparison runs and as a
fallback). It is also used off the main thread, and in a process that has
already opened a zenoh session (a second match played by the same process)
unless that process started a fork server first (match/zygote.py, as `arena
bench match` does): zenoh's runtime threads outlive the session, and a fork
would inherit its state without them (measured: the children of such a fork
did not play).
"""

from __future__ import annotations

import ctypes
import gc
import os
import signal
import subprocess
import sys
import threading
import time
import traceback
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from arena.match.run import Job

_PR_SET_PDEATHSIG = 1


def enabled() -> bool:
    """Fork, unless asked not to, off the main thread, or once this process has opened zenoh."""
    from arena.runtime.session import OPENED

    return (
        os.environ.get("ARENA_LAUNCH", "fork") != "exec"
        and threading.current_thread() is threading.main_thread()
        and not OPENED[0]
    )


def preload(kinds: set[str], strategies: set[str]) -> None:
    """Import what the match's processes import (their kinds, its strategies), once, before forking."""
    from arena.match import run  # noqa: F401
    from arena.processes import node_class
    from arena.strategies import registry

    for kind in kinds:
        node_class(kind)
    for name in strategies:
        registry.get(name)
    warm()


def warm() -> None:
    """Do once, in the parent, what every child did first (profiled: the imports that each child would repeat).

    Each line was on a child's path to the first tick: numpy.random (the engine's
    sensor noise imports it: ~80 ms), msgspec's
    type information for the configuration and for each message a node decodes
    (~40 ms in a robot). None of it depends on the match.
    """
    import msgspec
    import numpy.random  # noqa: F401

    from arena.config import MatchConfig
    from arena.schemas import messages

    try:  # only ever a head start: whatever fails here, each child does again (and reports) itself
        MatchConfig.from_json(MatchConfig().to_json())
        for value in vars(messages).values():
            if isinstance(value, type) and issubclass(value, messages.Base):
                msgspec.msgpack.Decoder(value)
    except Exception:
        pass


class ForkedProcess:
    """The `subprocess.Popen` subset the launcher uses, for a forked child."""

    def __init__(self, pid: int):
        self.pid = pid
        self.returncode: int | None = None

    def _reaped(self, status: int) -> int:
        self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def poll(self) -> int | None:
        if self.returncode is None:
            try:
                pid, status = os.waitpid(self.pid, os.WNOHANG)
            except ChildProcessError:
                self.returncode = self.returncode if self.returncode is not None else 0
                return self.returncode
            if pid != 0:
                return self._reaped(status)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        deadline = None if timeout is None else time.monotonic() + timeout
        delay = 0.001
        while self.poll() is None:
            if deadline is not None and time.monotonic() >= deadline:
                raise subprocess.TimeoutExpired(f"pid {self.pid}", timeout)
            time.sleep(delay)
            delay = min(delay * 2, 0.05)
        return self.returncode  # type: ignore[return-value]

    def send_signal(self, sig: int) -> None:
        if self.poll() is None:
            try:
                os.kill(self.pid, sig)
            except ProcessLookupError:
                pass

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def starter(count: int, kinds: set[str], strategies: set[str]) -> Starter | None:
    """How to start a match's `count` processes: this process's zygote if it has one
    (match/zygote.py), else a fork of this process if it can, else None (exec)."""
    from arena.match import zygote

    z = zygote.running()
    if z is not None:
        try:
            return Starter(z, count)
        except OSError:
            zygote.stop()
    if not enabled():
        return None
    preload(kinds, strategies)
    return Starter()


class Starter:
    """Forks the children of one match; `release` lets them open their sessions."""

    def __init__(self, zygote=None, count: int = 0) -> None:
        """Fork here, or with `zygote` (match/zygote.py) hand `count` jobs to its parked children."""
        self._go_r, self._go_w = os.pipe()
        self._count = 0
        self._frozen = False
        self._zygote = zygote
        self._parked = zygote.take(count) if zygote is not None else []
        if zygote is not None:
            return
        # The children inherit the parent's objects as frozen: their first full
        # collection (`settle_heap`, before the first tick) then scans only what they
        # made themselves, not every imported module's objects (~100 ms a child), and
        # leaves the shared pages uncopied. The parent thaws once it has forked.
        gc.collect()
        gc.freeze()
        self._frozen = True

    def fork(self, job: Job, log_path: Path) -> ForkedProcess:
        """Fork a child that runs `job`, logging to `log_path`."""
        if self._zygote is not None:
            self._count += 1
            return self._zygote.launch(self._parked.pop(), job, log_path, self._go_r)
        sys.stdout.flush()
        sys.stderr.flush()
        parent = os.getpid()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            _child(job, log_path, self._go_r, self._go_w, parent)
        self._count += 1
        return ForkedProcess(pid)

    @property
    def how(self) -> str:
        return "fork" if self._zygote is None else "zygote"

    def refill(self) -> None:
        """Have the zygote, if any, fork children for the next match (in the background)."""
        if self._zygote is not None:
            try:
                self._zygote.prepare(self._count)
            except OSError:
                pass

    def release(self) -> None:
        """The router is up: every forked child may start."""
        if self._go_w >= 0:
            os.write(self._go_w, b"g" * self._count)
            self.close()

    def close(self) -> None:
        for pid, sock in self._parked:  # more taken from a zygote than forked: they exit on end-of-file
            sock.close()
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:
                pass
        self._parked = []
        if self._frozen:
            gc.unfreeze()
            self._frozen = False
        # Forgotten before they are closed: a Ctrl-C between the two closes must not
        # leave a closed fd here for the launcher's `finally` to close again (EBADF,
        # which replaced the KeyboardInterrupt: exit 2 instead of 130, 1 run in ~20).
        fds = (self._go_r, self._go_w)
        self._go_r = self._go_w = -1
        for fd in fds:
            if fd >= 0:
                os.close(fd)


def retitle(argv: list[str]) -> None:
    """Show `python -m arena <argv>` as this process's command line (ps, /proc/<pid>/cmdline).

    A forked child would show the launcher's command. The kernel reads the
    command line from the memory of the original argv, so it is overwritten
    in place (truncated to its length, the rest NUL); the name (`comm`) is set
    too. Best effort: nothing depends on it but people and tests reading ps.
    """
    # Who it is first (`run robot --team a --robot 2`), the rest after, as far as it fits.
    head, rest = list(argv[:2]), list(argv[2:])
    for flag in ("--team", "--robot"):
        if flag in rest:
            i = rest.index(flag)
            head += rest[i : i + 2]
            del rest[i : i + 2]
    title = "\0".join(["python", "-m", "arena", *head, *rest]).encode()
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(15, ctypes.c_char_p(("arena-" + argv[1])[:15].encode()), 0, 0, 0)  # PR_SET_NAME
        stat = Path("/proc/self/stat").read_text()
        fields = stat[stat.rindex(")") + 2 :].split()
        start, end = int(fields[45]), int(fields[46])  # proc(5): arg_start (48), arg_end (49)
        size = end - start
        if size > 1:
            ctypes.memmove(start, title[: size - 1].ljust(size, b"\0"), size)
    except (OSError, ValueError, IndexError):
        pass


def _child(job: Job, log_path: Path, go_r: int, go_w: int, parent: int) -> None:
    code = 1
    try:
        if go_w >= 0:
            os.close(go_w)
        os.setsid()
        try:
            ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        except OSError:
            pass
        if os.getppid() != parent:  # the launcher died before the prctl
            os._exit(1)
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGCHLD):
            signal.signal(sig, signal.SIG_DFL)
        log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.dup2(log, 1)
        os.dup2(log, 2)
        os.close(log)
        os.close(null)
        if os.read(go_r, 1) != b"g":  # the launcher is gone: nothing to join
            os._exit(1)
        os.close(go_r)
        # Named `arena run ...` only now: whoever sees one (ps, a test) can count on the router being up.
        retitle(job.argv())
        from arena.match.run import start

        code = start(job)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except KeyboardInterrupt:  # Ctrl-C reached it before it had its own session: the launcher says so
        code = 130
    except BaseException:
        traceback.print_exc()
        code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)
