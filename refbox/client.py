"""A base station's end of a RefBox connection: connect, reconnect, read commands.

Used by `--refbox-follow` (our referee connects to a real RefBox) and by
`--via-refbox` (our base stations connect to the bridge). It runs on its own
thread, so nothing ever blocks the caller: `drain()` hands over the commands
(rules/refbox_protocol.py's `Command`, JSON or legacy framing) that arrived
since the last call; `send()` writes a worldstate.
"""

from __future__ import annotations

import logging
import socket
import threading
import time

from arena.rules import refbox_protocol as rp


def unreachable(host: str, port: int, timeout: float = 2.0) -> str:
    """Why nothing accepts a TCP connection at host:port now ("" if something does): said before a match starts."""
    try:
        with socket.create_connection((host, port), timeout=timeout):
            return ""
    except TimeoutError:
        return f"no answer within {timeout:g} s"
    except OSError as exc:
        return exc.strerror or type(exc).__name__


class RefboxClient:
    """A base station's end of the RefBox connection: connects (and reconnects), reads commands.

    Runs on its own thread; `drain()` hands over what arrived. Nothing blocks the caller.
    """

    def __init__(self, host: str, port: int, log: logging.Logger, source: str = "", name: str = "refbox"):
        self.host, self.port, self.source = host, port, source
        self.log = log
        self._lock = threading.Lock()
        self._got: list[rp.Command] = []
        self.errors: list[str] = []
        self.connected = threading.Event()
        self._stop = threading.Event()
        self.sock: socket.socket | None = None
        self.thread = threading.Thread(target=self._run, name=f"{name}-client", daemon=True)
        self.thread.start()

    def drain(self) -> list[rp.Command]:
        with self._lock:
            out, self._got = self._got, []
        return out

    def send(self, data: bytes) -> bool:
        """Send to the RefBox (a worldstate); False when not connected or the send would block."""
        sock = self.sock
        if sock is None:
            return False
        try:
            sock.sendall(data)
            return True
        except OSError:
            return False

    def close(self) -> None:
        self._stop.set()
        sock = self.sock
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        self.thread.join(timeout=2.0)

    def _connect(self) -> socket.socket | None:
        try:
            src = (self.source, 0) if self.source else None
            sock = socket.create_connection((self.host, self.port), timeout=1.0, source_address=src)
        except OSError:
            return None
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.settimeout(0.5)
        return sock

    def _run(self) -> None:
        warned = False
        while not self._stop.is_set():
            sock = self._connect()
            if sock is None:
                if not warned:
                    self.log.warning("refbox: cannot reach the RefBox at %s:%d yet; retrying", self.host, self.port)
                    warned = True
                self._stop.wait(0.2)
                continue
            self.sock = sock
            self.connected.set()
            self.log.warning("refbox: connected to the RefBox at %s:%d", self.host, self.port)
            reader = rp.CommandReader()
            while not self._stop.is_set():
                try:
                    data = sock.recv(4096)
                except TimeoutError:
                    continue
                except OSError:
                    break
                if not data:
                    break
                cmds = reader.feed(data)
                if reader.errors:
                    for e in reader.errors:
                        self.log.error("refbox: from the RefBox: %s", e)
                    self.errors.extend(reader.errors)
                    reader.errors.clear()
                if cmds:
                    with self._lock:
                        self._got.extend(cmds)
            self.sock = None
            sock.close()
            if not self._stop.is_set():
                self.log.warning(
                    "refbox: the RefBox at %s:%d closed the connection; reconnecting", self.host, self.port
                )
                time.sleep(0.2)
