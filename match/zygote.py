"""A fork server: every match of a long-lived process gets forked, warm children.

`match/forkstart.py` forks a match's processes from the launcher itself, which
works only while the launcher has never opened zenoh: zenoh's runtime threads
outlive a session and a fork lacks them. A process that plays match after match
(`arena bench match`, a tournament worker) opens a router for its first one, so
from the second match on it had to start eleven interpreters again.

The zygote is forked from such a process *before* it opens zenoh. It imports and
warms everything (`forkstart.preload`), freezes its heap and then, on request,
prepares children ahead of time: each is parked, already forked, on a socket of
its own, until the launcher hands it a job (the typed `Job` of `arena run <kind> ...`, log
file, environment, working directory and the match's release pipe). Launching a
match is then a few messages; the forking happened during the previous match.

Rules kept:
* The launcher is the children's real parent, as with `forkstart`: it sets
  `PR_SET_CHILD_SUBREAPER`, the zygote double-forks every child, and the
  intermediate exits at once, so the kernel hands the child to the launcher.
  `forkstart.ForkedProcess` then waits for it like `subprocess.Popen` does.
* Nothing outlives the launcher: the zygote has `PR_SET_PDEATHSIG` and reads
  end-of-file from its socket when the launcher goes; a parked child reads
  end-of-file from its own socket and exits; a child with a job gets
  `PR_SET_PDEATHSIG` against the launcher, as a forked child does.
* The zygote and parked children hold none of the launcher's descriptors (a
  caller reading the launcher's stdout to its end must not wait for them).
* Any failure of the zygote is the launcher's cue to start the match another way
  (`launch`: fork or exec), never an error.
"""

from __future__ import annotations

import atexit
import ctypes
import gc
import json
import os
import signal
import socket
import sys
from pathlib import Path

import msgspec

from arena.match import forkstart
from arena.match.run import Job

_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36


def _prctl(option: int, value: int) -> bool:
    try:
        return ctypes.CDLL("libc.so.6", use_errno=True).prctl(option, value, 0, 0, 0) == 0
    except OSError:
        return False


class Zygote:
    """The launcher's side: a pool of parked children, refilled by the zygote process."""

    def __init__(self, kinds: set[str], strategies: set[str]):
        if not forkstart.enabled():
            raise RuntimeError("a zygote must be forked before this process opens zenoh, on the main thread")
        if not _prctl(_PR_SET_CHILD_SUBREAPER, 1):
            raise RuntimeError("cannot become the children's subreaper")
        self.launcher = os.getpid()
        self._ctl, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the zygote: never returns
            self._ctl.close()
            _serve(theirs, self.launcher, kinds, strategies)
        theirs.close()
        self.pid = pid
        self._parked: list[tuple[int, socket.socket]] = []
        self._asked = 0

    def alive(self) -> bool:
        try:
            return os.waitpid(self.pid, os.WNOHANG)[0] == 0
        except ChildProcessError:
            return False

    def prepare(self, n: int) -> None:
        """Ask for `n` more parked children (forked by the zygote in the background)."""
        want = n - (len(self._parked) + self._asked)
        if want > 0:
            self._ctl.sendall(b"%d" % want)
            self._asked += want

    def _receive(self, block: bool) -> bool:
        self._ctl.setblocking(block)
        try:
            msg, fds, _, _ = socket.recv_fds(self._ctl, 64, 1)
        except (BlockingIOError, InterruptedError):
            return False
        finally:
            self._ctl.setblocking(True)
        if not msg:
            raise OSError("the zygote is gone")
        self._asked -= 1
        if not fds:  # one that died as it was forked
            return True
        child = socket.socket(fileno=fds[0])
        pid = int(msg)
        try:
            if os.waitpid(pid, os.WNOHANG)[0] != 0:  # died while parked
                child.close()
                return True
        except ChildProcessError:  # not ours (no subreaper after all): unusable
            child.close()
            raise OSError(f"parked child {pid} is not this process's child") from None
        self._parked.append((pid, child))
        return True

    def ready(self, n: int) -> None:
        """Wait until `n` children are parked (the zygote has imported everything and forked them)."""
        self.prepare(n)
        while len(self._parked) < n:
            self.prepare(n)
            self._receive(block=True)

    def take(self, n: int) -> list[tuple[int, socket.socket]]:
        """`n` parked children, waiting for those still being forked."""
        self.prepare(n)
        while self._receive(block=False):
            pass
        while len(self._parked) < n:
            self.prepare(n)  # in place of any that died while parked
            self._receive(block=True)
        taken, self._parked = self._parked[:n], self._parked[n:]
        return taken

    @staticmethod
    def launch(child: tuple[int, socket.socket], job: Job, log_path: Path, go_r: int) -> forkstart.ForkedProcess:
        """Give a parked child its job, logging to `log_path`, started by the release pipe."""
        pid, sock = child
        msg = {"job": msgspec.to_builtins(job), "log": str(log_path), "cwd": os.getcwd(), "env": dict(os.environ)}
        try:
            socket.send_fds(sock, [json.dumps(msg).encode()], [go_r])
        finally:
            sock.close()
        return forkstart.ForkedProcess(pid)

    def close(self) -> None:
        for pid, sock in self._parked:
            sock.close()  # the parked child reads end-of-file and exits
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:
                pass
        self._parked = []
        self._ctl.close()
        try:
            os.kill(self.pid, signal.SIGTERM)
            os.waitpid(self.pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass


def _serve(ctl: socket.socket, launcher: int, kinds: set[str], strategies: set[str]) -> None:
    """The zygote process: fork parked children on request until the launcher goes."""
    code = 0
    try:
        os.setsid()  # Ctrl-C reaches the launcher only
        _prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != launcher:
            os._exit(1)
        null = os.open(os.devnull, os.O_RDWR)
        for fd in (0, 1, 2):
            os.dup2(null, fd)
        keep = ctl.fileno()
        os.closerange(3, keep)
        os.closerange(keep + 1, 1 << 16)
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGCHLD):
            signal.signal(sig, signal.SIG_DFL)
        forkstart.preload(kinds, strategies)
        gc.collect()
        gc.freeze()
        while True:
            msg = ctl.recv(64)
            if not msg:
                break
            for _ in range(int(msg)):
                _park_one(ctl, launcher)
    except BaseException:
        code = 1
    os._exit(code)


def _park_one(ctl: socket.socket, launcher: int) -> None:
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    middle = os.fork()
    if middle == 0:
        try:
            if os.fork() == 0:
                ctl.close()
                ours.close()
                _parked(theirs, launcher)
        finally:
            os._exit(0)  # the child is orphaned now: the kernel hands it to the launcher
    theirs.close()
    os.waitpid(middle, 0)
    try:
        pid = int(ours.recv(32))  # the child's first word; it is the launcher's now
        socket.send_fds(ctl, [b"%d" % pid], [ours.fileno()])
    except ValueError:
        ctl.sendall(b"-")  # it died at once; the launcher asks for another
    finally:
        ours.close()


def _parked(sock: socket.socket, launcher: int) -> None:
    """A parked child: wait for a job, then run it (forkstart's child)."""
    code = 1
    try:
        sock.sendall(b"%d" % os.getpid())
        msg, fds, _, _ = socket.recv_fds(sock, 1 << 20, 1)
        sock.close()
        if not msg or not fds:
            os._exit(0)  # the launcher is done with us
        job = json.loads(msg)
        os.chdir(job["cwd"])
        os.environ.clear()
        os.environ.update(job["env"])
        forkstart._child(msgspec.convert(job["job"], Job), Path(job["log"]), fds[0], -1, launcher)
    except BaseException:
        pass
    os._exit(code)


_ONE: list[Zygote] = []
COMMON_KINDS = ("engine", "referee", "basestation", "robot", "recorder")  # the others import on demand


def start(kinds: set[str] | None = None, strategies: set[str] | None = None, ready: int = 0) -> Zygote | None:
    """Start this process's zygote (before it opens zenoh); None where forking is off or impossible.

    `ready`: return once that many children are parked, so that the first match starts warm too."""
    from arena.strategies import registry

    if _ONE:
        return _ONE[0]
    if not forkstart.enabled():
        return None
    try:
        z = Zygote(
            set(COMMON_KINDS) if kinds is None else kinds,
            set(registry.builtin_strategies()) if strategies is None else strategies,
        )
    except (OSError, RuntimeError):
        return None
    _ONE.append(z)
    # Reaped before this process exits, so that the zygote's CPU (its imports, its forks)
    # and its parked children's count in this process's children, as a whole-process timing reads them.
    atexit.register(stop)
    try:
        z.ready(ready)
    except OSError:
        stop()
        return None
    return z


def stop() -> None:
    """End this process's zygote and its parked children (also when it has failed)."""
    while _ONE:
        _ONE.pop().close()


def running() -> Zygote | None:
    """This process's zygote, if it has one that still runs (and launches are not forced to exec)."""
    if not _ONE or os.environ.get("ARENA_LAUNCH", "fork") == "exec":
        return None
    if not _ONE[0].alive():
        stop()
        return None
    return _ONE[0]
