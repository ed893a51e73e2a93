"""The RefBox's base-station server: a real TCP server on its own thread.

What it does, as the MSL RefBox does it (rules/refbox_protocol.py has the
sources): a base station connects; it is identified by its source address
(`a.b.c.*`) against the team table, or, without a table, takes the first free
side (team a, then b). An unknown team, or a third one, gets RESET and is
disconnected, and the refusal is logged and counted. A known one gets WELCOME.
Every command our referee issues then goes to every connected base station,
each in its own protocol (2020 JSON or legacy characters), each command in its
own `send` with TCP_NODELAY. Whatever a base station sends is read as
NUL-terminated worldstates and validated; the results are handed to the
caller (`drain`), the bad ones counted by team and reason.

Nothing here ever blocks the caller: `broadcast` queues, the server thread
writes. A base station that stops reading is cut off once 1 MiB is queued for it.

No input ends or stalls the server: every message is bounded (`MAX_UNTERMINATED`
characters, `MAX_DEPTH` levels of nesting), parsing is linear in its length, one
connection is read `READ_SLICE` bytes at a time between the others' turns, and every
decode error is counted by reason. A base station that misbehaves is disconnected
and the match goes on: one that nests too deep, sends `MAX_ERRORS` bad messages,
sends more than `MAX_RATE` bytes a second on average (`flooding`), or whose input
raises anything unforeseen (counted as `unreadable`, with the exception's type in the log).
"""

from __future__ import annotations

import logging
import queue
import selectors
import socket
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field

from arena.config import RefboxParams
from arena.refbox.follow import VIA_TEAMS
from arena.rules import refbox_protocol as rp

MAX_QUEUED = 1 << 20  # [bytes] per client: beyond this the client is disconnected
MAX_ERRORS = 1000  # bad messages from one connection: then it is disconnected
# [bytes/s] what one connection may send on average, and [bytes] in one burst: an MSL worldstate is
# a few kB at 10 to 40 Hz (well under 0.5 MB/s); a burst of 2 MB holds twenty messages of the
# RefBox's largest size. A connection that sends more is flooding and is disconnected. Parsing
# the costliest shape at this rate takes about a tenth of a core (`arena bench refbox`).
MAX_RATE = 1 << 20
MAX_BURST = 2 << 20
READ_SLICE = 65536  # [bytes] read and parsed from one connection before the next one's turn
DISCONNECTS = ("too-deep",)  # reasons no honest base station gives: disconnected at the first
TEAMS = ("a", "b")


@dataclass
class Client:
    sock: socket.socket
    address: str
    side: str
    protocol: str
    name: str = ""
    reader: rp.WorldstateReader = field(default_factory=rp.WorldstateReader)
    out: bytearray = field(default_factory=bytearray)
    errors: int = 0  # bad messages on this connection
    budget: float = MAX_BURST  # [bytes] it may still send now (refilled at MAX_RATE)
    since: float = field(default_factory=time.monotonic)  # when `budget` was last refilled

    def spend(self, n: int, now: float) -> bool:
        """Take `n` bytes off the budget; False when that overdraws it (the client floods)."""
        self.budget = min(MAX_BURST, self.budget + (now - self.since) * MAX_RATE) - n
        self.since = now
        return self.budget >= 0


def check_listen(endpoint: str) -> None:
    """Fail early, with one line, when the bridge could not listen on `endpoint` (a busy port)."""
    host, port = rp.parse_endpoint(endpoint)
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    try:
        with socket.socket(family) as s:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            s.bind((host, port))
    except OSError as exc:
        raise rp.ProtocolError(f"--refbox {endpoint}: cannot listen there: {exc.strerror}") from None


class BridgeServer:
    def __init__(
        self,
        host: str,
        port: int,
        params: RefboxParams,
        log: logging.Logger,
        budget_clock: Callable[[], float] = time.monotonic,
    ):
        """`budget_clock`: the seconds a connection's byte budget refills by (`Client.spend`); a test
        stops it to cut a flood off at `MAX_BURST` bytes whatever the host's load."""
        self.params = params
        self.log = log
        self._budget_clock = budget_clock
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        try:
            self.sock = socket.create_server((host, port), family=family, backlog=8)
        except OSError as exc:
            raise rp.ProtocolError(f"cannot listen on tcp/{host}:{port}: {exc.strerror}") from None
        self.sock.setblocking(False)
        self.port = self.sock.getsockname()[1]
        self.sel = selectors.DefaultSelector()
        self.sel.register(self.sock, selectors.EVENT_READ, "accept")
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self.sel.register(self._wake_r, selectors.EVENT_READ, "wake")
        self.clients: dict[socket.socket, Client] = {}
        self.targets = {t: self._default_target(t) for t in TEAMS}
        self._outq: queue.SimpleQueue[tuple[str, str, int]] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._results: list[tuple[str, str, rp.WorldstateResult, float]] = []
        self._stop = False
        self.connected = threading.Event()  # set whenever a client is accepted
        self.counts: Counter[str] = Counter()  # connections, refused, commands sent, worldstates
        self.errors: dict[str, Counter[str]] = {t: Counter() for t in TEAMS}  # bad worldstates by reason
        self.thread = threading.Thread(target=self._run, name="refbox-server", daemon=True)
        self.thread.start()

    # ------------------------------------------------------------ caller side
    def broadcast(self, command: str, team: str = "", robot_id: int = -1) -> None:
        """Queue one command of our referee for every connected base station."""
        self._outq.put((command, team if command in rp.TEAM_COMMANDS else "", robot_id))
        try:
            self._wake_w.send(b"x")
        except OSError:  # the server has stopped: nobody to send to, and the match goes on
            pass

    def drain(self) -> list[tuple[str, str, rp.WorldstateResult, float]]:
        """(team, address, result, time.monotonic() when read) of every message read since the last call."""
        with self._lock:
            out, self._results = self._results, []
        return out

    def sides(self) -> int:
        with self._lock:
            return sum(1 for c in self.clients.values() if c.side)

    def close(self, linger: float = 1.0) -> None:
        """Flush what is queued (up to `linger` seconds), then close every connection."""
        deadline = time.monotonic() + linger
        while time.monotonic() < deadline and (not self._outq.empty() or any(c.out for c in self._snapshot())):
            time.sleep(0.01)
        self._stop = True
        self._wake_w.send(b"x")
        self.thread.join(timeout=2.0)

    def _snapshot(self) -> list[Client]:
        with self._lock:
            return list(self.clients.values())

    # ------------------------------------------------------------ server side
    def _default_target(self, team: str) -> str:
        colour = rp.colour_of(team, self.params.swap)
        return self.params.target_cyan if colour == "cyan" else self.params.target_magenta

    def _run(self) -> None:
        try:
            while not self._stop:
                for key, mask in self.sel.select(timeout=0.5):
                    if key.data == "accept":
                        self._accept()
                    elif key.data == "wake":
                        try:
                            self._wake_r.recv(4096)
                        except BlockingIOError:
                            pass
                    else:
                        client = self.clients.get(key.fileobj)
                        if client is None:
                            continue
                        try:
                            if mask & selectors.EVENT_READ:
                                self._read(client)
                            if mask & selectors.EVENT_WRITE and client.sock in self.clients:
                                self._flush(client)
                        except Exception as exc:  # no client's input may end the server
                            self.errors[client.side]["unreadable"] += 1
                            self._drop(client, f"unreadable input ({type(exc).__name__}: {str(exc)[:80]})")
                self._send_queued()
        finally:
            self._close_all()
            self.sel.close()
            self.sock.close()
            self._wake_r.close()
            self._wake_w.close()

    def _accept(self) -> None:
        try:
            sock, addr = self.sock.accept()
        except (BlockingIOError, ConnectionAbortedError):
            return
        ip = addr[0]
        side, protocol, name, why = self._identify(ip)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        if not side:
            self.counts["refused"] += 1
            self.log.error("refbox: refused base station %s: %s; sent RESET", ip, why)
            try:
                sock.sendall(rp.encode_json("RESET"))
            except OSError:
                pass
            sock.close()
            return
        sock.setblocking(False)
        client = Client(sock, ip, side, protocol, name, since=self._budget_clock())
        with self._lock:
            self.clients[sock] = client
        self.sel.register(sock, selectors.EVENT_READ, "client")
        self.counts["connections"] += 1
        colour = rp.colour_of(side, self.params.swap)
        self.log.warning("refbox: base station %s connected as team %s (%s, %s protocol)", ip, side, colour, protocol)
        self._send(client, "WELCOME", side, -1)
        self.connected.set()

    def _identify(self, ip: str) -> tuple[str, str, str, str]:
        """(side, protocol, name, why-not) for a new connection."""
        taken = {c.side for c in self.clients.values()}
        table = self.params.teams + (VIA_TEAMS if self.params.via else ())
        if table:
            entry = rp.identify(ip, table)
            if entry is None:
                return "", "", "", f"unknown team: {rp.subnet_of(ip) or ip} is in no UnicastAddr of the team table"
            side = entry.side or next((t for t in TEAMS if t not in taken), "")
            if not side or side in taken:
                return "", "", "", f"team {entry.name or entry.address}: side {side or 'a/b'} is already connected"
            if entry.target:
                self.targets[side] = entry.target
            return side, entry.protocol, entry.name, ""
        side = next((t for t in TEAMS if t not in taken), "")
        if not side:
            return "", "", "", "both teams are already connected"
        return side, self.params.protocol_a if side == "a" else self.params.protocol_b, "", ""

    def _send_queued(self) -> None:
        while True:
            try:
                command, team, robot_id = self._outq.get_nowait()
            except queue.Empty:
                return
            for client in list(self.clients.values()):
                self._send(client, command, team, robot_id)

    def _send(self, client: Client, command: str, team: str, robot_id: int) -> None:
        if client.protocol == "legacy":
            data = rp.encode_legacy(command, rp.colour_of(team, self.params.swap) if team else "")
            if data is None:
                self.counts["not-in-legacy-protocol"] += 1
                return
        else:
            data = rp.encode_json(command, self.targets[team] if team else "", robot_id if robot_id >= 0 else None)
        self.counts[f"commands_to_{client.side}"] += 1
        if client.out:  # already behind: queue after what is waiting
            client.out += data
        else:
            try:
                n = client.sock.send(data)  # one send per command (known clients read one recv as one message)
            except BlockingIOError:
                n = 0
            except OSError as exc:
                self._drop(client, f"send failed: {exc}")
                return
            if n < len(data):
                client.out += data[n:]
                self.sel.modify(client.sock, selectors.EVENT_READ | selectors.EVENT_WRITE, "client")
        if len(client.out) > MAX_QUEUED:
            self._drop(client, f"not reading: {len(client.out)} bytes queued")

    def _flush(self, client: Client) -> None:
        try:
            n = client.sock.send(client.out)
        except BlockingIOError:
            return
        except OSError as exc:
            self._drop(client, f"send failed: {exc}")
            return
        del client.out[:n]
        if not client.out:
            self.sel.modify(client.sock, selectors.EVENT_READ, "client")

    def _read(self, client: Client) -> None:
        try:
            data = client.sock.recv(READ_SLICE)
        except BlockingIOError:
            return
        except OSError as exc:
            self._drop(client, f"receive failed: {exc}")
            return
        if not data:
            self._drop(client, "closed the connection")
            return
        if not client.spend(len(data), self._budget_clock()):
            self.errors[client.side]["flooding"] += 1
            self._drop(client, f"misbehaving (flooding: more than {MAX_RATE >> 20} MB/s)")
            return
        self._take(client, data)

    def _take(self, client: Client, data: bytes) -> None:
        now = time.monotonic()
        results = client.reader.feed(data)
        why = ""
        for r in results:
            if r.doc is None:
                self.errors[client.side][r.reason] += 1
                client.errors += 1
                if client.errors <= rp.LOG_FIRST_ERRORS:
                    self.log.error(
                        "refbox: team %s worldstate error %s: %s (%r)", client.side, r.reason, r.detail, r.raw[:60]
                    )
                if r.reason in DISCONNECTS or client.errors >= MAX_ERRORS:
                    why = f"{r.reason}: {r.detail}" if r.reason in DISCONNECTS else f"{client.errors} bad messages"
            else:
                self.counts[f"worldstates_{client.side}"] += 1
        if results:
            with self._lock:
                self._results.extend((client.side, client.address, r, now) for r in results)
        if why and client.sock in self.clients:
            self._drop(client, f"misbehaving ({why})")

    def _close_all(self, grace: float = 0.5) -> None:
        """End of match: half-close every connection, read what is still in flight, close.
        (Closing a socket with unread input resets it, and the peer can lose our last commands.)"""
        clients = list(self.clients.values())
        for c in clients:
            try:
                c.sock.shutdown(socket.SHUT_WR)
            except OSError:
                pass
        deadline = time.monotonic() + grace
        open_ = clients
        while open_ and time.monotonic() < deadline:
            still = []
            for c in open_:
                try:
                    data = c.sock.recv(65536)
                except BlockingIOError:
                    still.append(c)
                    continue
                except OSError:
                    continue
                if data:  # what the base station sent before it saw our end: still counts
                    self._take(c, data)
                    still.append(c)
            open_ = still
            if open_:
                time.sleep(0.02)
        for c in clients:
            self._drop(c, "", quiet=True)

    def _drop(self, client: Client, why: str, quiet: bool = False) -> None:
        with self._lock:
            self.clients.pop(client.sock, None)
        try:
            self.sel.unregister(client.sock)
        except (KeyError, ValueError):
            pass
        client.sock.close()
        if not quiet:
            self.counts["disconnected"] += 1
            self.log.warning("refbox: team %s (%s) disconnected: %s", client.side, client.address, why)
