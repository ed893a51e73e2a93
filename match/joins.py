"""Processes started by hand (`--external`): the addresses they can reach, the
command to type for each, and waiting until each has joined."""

from __future__ import annotations

import time
from pathlib import Path

import zenoh

from arena.config import ProcessId
from arena.match.children import Child, JoinError
from arena.match.run import run_job
from arena.schemas.keys import Keys


def lan_addresses() -> list[str]:
    """This machine's IPv4 addresses other than loopback and link-local (what a robot on the LAN can reach)."""
    import fcntl
    import socket
    import struct

    found: list[str] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for _, name in socket.if_nameindex():
            try:
                packed = fcntl.ioctl(s.fileno(), 0x8915, struct.pack("256s", name[:15].encode()))  # SIOCGIFADDR
            except OSError:
                continue  # no IPv4 address on this interface
            addr = socket.inet_ntoa(packed[20:24])
            if not addr.startswith(("127.", "169.254.")) and addr not in found:
                found.append(addr)
    return found


def robot_endpoints(endpoint: str) -> tuple[list[str], bool]:
    """The endpoints a process on another computer can connect to, and whether it needs `--mode client`.

    `tcp/0.0.0.0:P` (every interface) becomes one endpoint per LAN address; a
    loopback or unix-socket endpoint stays as it is, for a process on this
    machine, which can mesh with the others as a peer. A process on another
    computer cannot reach the others' loopback ports, so it talks through the
    router: `--mode client` (docs/architecture.md).
    """
    proto, _, address = endpoint.partition("/")
    host, _, port = address.rpartition(":")
    if proto == "unixsock-stream" or host.startswith(("127.", "localhost", "[::1]")):
        return [endpoint], False
    if host in ("0.0.0.0", "[::]"):
        lan = lan_addresses()
        if not lan:  # no network but loopback: only this machine can join
            return [f"{proto}/127.0.0.1:{port}"], False
        return [f"{proto}/{a}:{port}" for a in lan], True
    return [endpoint], True


class Joins:
    """Which processes of the match have their liveliness token (who is there), seen from the router."""

    def __init__(self, session, keys: Keys, external: set[ProcessId], announce) -> None:
        self.external = {str(p) for p in external}
        self.alive: set[str] = set()
        self.announce = announce or (lambda text: None)
        self._subs = []
        if self.external:
            self._subs.append(session.liveliness().declare_subscriber(keys.alive_all(), self._on_alive, history=True))
            self._subs.append(session.declare_subscriber(keys.refused_all(), self._on_refused))

    def _on_alive(self, sample) -> None:
        name = str(sample.key_expr).split("/alive/", 1)[-1]
        if sample.kind == zenoh.SampleKind.PUT:
            self.alive.add(name)
            if name in self.external:
                self.announce(f"external {name} joined")
        else:
            self.alive.discard(name)

    def _on_refused(self, sample) -> None:  # said by a newcomer that found no identity to claim (run.py)
        name = str(sample.key_expr).split("/refused/", 1)[-1]
        newcomer = sample.payload.to_bytes().decode(errors="replace")
        self.announce(f"refused a second {name} (the newcomer on {newcomer}): one is already running")

    def missing(self) -> list[str]:
        return sorted(self.external - self.alive)

    def wait(self, timeout: float, children: list[Child]) -> None:
        """Until every external process has joined; JoinError after `timeout`.

        The children wait as long at their start barrier, but their clocks
        start later (after spawn and imports), so this gives up first and the
        message names who never came. A child that fails meanwhile is
        supervise()'s to report.
        """
        deadline = time.monotonic() + timeout
        while self.missing() and all(c.popen.poll() is None for c in children):
            if time.monotonic() > deadline:
                raise JoinError(
                    f"external {', '.join(self.missing())} did not join within {timeout:g} s "
                    "(start it with the command printed above)"
                )
            time.sleep(0.1)

    def close(self) -> None:
        for sub in self._subs:
            sub.undeclare()


def instructions(
    external: list[ProcessId],
    match: str,
    endpoint: str,
    record: str = "",
    credentials: dict[str, Path] | None = None,
    secure: bool = False,
) -> str:
    """What to type on the robot's computer: a command per --external process, with an address it can reach."""
    endpoints, client = robot_endpoints(endpoint)
    n = len(external)
    lines = [f"waiting for {n} external process{'es' if n != 1 else ''}; start {'each' if n != 1 else 'it'} with:"]
    for p in external:
        cred = str(credentials[str(p)]) if credentials else None
        argv = run_job(p, match, endpoints[0], record=record, credentials=cred).argv()
        if client and not secure:  # a secure match's credentials file says client mode
            argv += ["--mode", "client"]
        lines.append("  arena " + " ".join(argv))
    if credentials:
        lines.append("  (--credentials: that process's own key; copy the file to its computer and to nobody else)")
    if len(endpoints) > 1:
        lines.append(f"  (this machine is also reachable as: {', '.join(e.split('/', 1)[1] for e in endpoints[1:])})")
    return "\n".join(lines)
