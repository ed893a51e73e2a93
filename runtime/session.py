"""Zenoh session factory, isolated by default.

Multicast scouting is off unless asked for, and every session has explicit
endpoints, so twenty matches on one machine, or CI next to other zenoh
processes on port 7447, never hear each other. On top of that every match has
its own key prefix (schemas/keys.py).

Topology used by `arena match`: a router listens on a per-match endpoint (a
unix socket in the match's temp dir, or a TCP port); every process opens a
*peer* session that connects to it and listens on an ephemeral loopback port,
so gossip scouting (over the router link only) lets the peers open direct links
to one another, which is faster per tick than clients through the router
(docs/performance.md, "Measurements behind design choices"). A hardware-in-the-loop process on another machine uses
`--mode client` and talks through the router.

Liveliness is how a match learns that a process is gone: a crashed process's
token vanishes within milliseconds, a hung one's (SIGSTOP, power loss, cut
cable) when its lease expires. The lease is 6 s instead of zenoh's 10 s; keep-
alives only flow on links that carry nothing else, so the lockstep traffic
pays nothing for it. A 2 s lease lost healthy peers on an overloaded host
(docs/performance.md, "Measurements behind design choices"). A match's
`timing.lease` sets it for every process that opens its session knowing the
configuration (`arena match`'s router and children, `arena run --config`).
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field

import zenoh

from arena.config import ConfigError

_PROTOCOLS = ("tcp", "udp", "tls", "quic", "ws", "unixsock-stream", "unixpipe", "vsock")


class EndpointError(ConfigError):
    """An endpoint that cannot be used: malformed, busy, or refused (a user error, exit 2)."""


def check_endpoint(flag: str, text: str) -> str:
    """`text` if it is a zenoh endpoint we can use, else EndpointError naming `flag`."""
    proto, _, address = text.partition("/")
    hint = "use e.g. tcp/192.168.1.10:7447 or unixsock-stream/PATH"
    if proto not in _PROTOCOLS or not address:
        raise EndpointError(f"{flag} {text}: not a zenoh endpoint ({hint})")
    if proto in ("tcp", "udp", "tls", "quic", "ws"):
        host, sep, port = address.split("?", 1)[0].split("#", 1)[0].rpartition(":")
        if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
            raise EndpointError(f"{flag} {text}: needs HOST:PORT with a port in 0..65535 ({hint})")
    return text


def listening(endpoint: str, timeout: float = 1.0) -> bool:
    """Does anything accept a connection at `endpoint` (tcp, tls, ws or a unix socket)?

    Tells "no router there" from "a router that refused us": zenoh reports both
    as "Unable to connect". The probe opens a plain connection and closes it.
    """
    import socket

    proto, _, address = endpoint.partition("/")
    address = address.split("?", 1)[0].split("#", 1)[0]
    try:
        if proto == "unixsock-stream":
            with socket.socket(socket.AF_UNIX) as s:
                s.settimeout(timeout)
                s.connect(address)
            return True
        if proto in ("tcp", "tls", "ws"):
            host, _, port = address.rpartition(":")
            with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
                return True
    except (OSError, ValueError):
        return False
    return False


def zenoh_reason(exc: Exception) -> str:
    """zenoh's error text without its Rust wrappers and source paths."""
    text = str(exc)
    inner = re.search(r'msg: "(.*?)"', text)
    if inner:
        text = inner.group(1)
    text = re.sub(r"\s+at /\S+?\.rs:\d+\.?", "", text)
    return text.strip(" .[]")


@dataclass(frozen=True)
class NetConfig:
    mode: str = "peer"  # peer | client | router
    connect: tuple[str, ...] = ()
    listen: tuple[str, ...] = ()
    multicast: bool = False  # multicast scouting; off keeps matches apart
    extra: tuple[tuple[str, str], ...] = field(default=())  # (json5 path, json5 value) from --cfg
    base: str = ""  # a credentials fragment (JSON), the starting point (runtime/credentials.py)
    lease: float = 6.0  # [s] the link lease: unheard this long, a peer is gone (the match's `timing.lease`)

    def zenoh_config(self) -> zenoh.Config:
        c = zenoh.Config.from_json5(self.base) if self.base else zenoh.Config()
        c.insert_json5("mode", json.dumps(self.mode))
        c.insert_json5("scouting/multicast/enabled", "true" if self.multicast else "false")
        c.insert_json5("connect/endpoints", json.dumps(list(self.connect)))
        listen = list(self.listen)
        if not listen and self.mode == "peer" and self.connect:
            # An ephemeral loopback port so that other peers of this match can
            # open a direct link to us; nothing outside this machine can.
            listen = ["tcp/127.0.0.1:0"]
        c.insert_json5("listen/endpoints", json.dumps(listen))
        c.insert_json5("transport/link/tx/lease", str(round(self.lease * 1000)))
        c.insert_json5("transport/link/tx/keep_alive", "4")
        if self.mode == "router" and not self.multicast and not self.connect:
            # zenoh 1.10 starts a router with a plain sleep of `scouting/delay` (500 ms by
            # default), meant for scouting and connecting to other routers. With neither, it
            # only delayed every match's start by half a second.
            c.insert_json5("scouting/delay", "0")
        for path, value in self.extra:
            c.insert_json5(path, value)
        return c


# Eleven processes share two cores. zenoh's default is a pool of threads per
# runtime (rx, tx, app, acc, net), so every message wakes one thread to write it
# and another to read it. Handing every runtime over to one thread per process
# lets a message go out from the thread that is already awake (faster, less CPU:
# docs/performance.md, "Measurements behind design choices"). A user's own ZENOH_RUNTIME wins.
ONE_THREAD_RUNTIME = "(rx:(worker_threads:1),acc:(handover:rx),tx:(handover:rx),net:(handover:rx),app:(handover:rx))"


# A client (a secure match, containers) sends everything over its one link to the
# router, tap batches of ~100 kB included. With tx handed over to rx, a reactive
# node's BLOCK put on zenoh's only thread waited for queue room that only that
# thread could make, and in secure recorded matches the engine stalled until its
# lease expired. A transmit thread of its own ends that; every router gets one too
# (a secure match's carries every frame, a peer match's relays to spectators) (docs/performance.md, "Measurements
# behind design choices").
CLIENT_RUNTIME = "(rx:(worker_threads:1),acc:(handover:rx),tx:(worker_threads:1),net:(handover:rx),app:(handover:rx))"

# Whether this process has opened a zenoh session: zenoh's runtime threads then
# exist, and a fork of this process would not have them (match/forkstart.py).
OPENED = [False]


def check_runtime_variable(text: str) -> None:
    """A user's ZENOH_RUNTIME must at least look like zenoh's RON tuple: a bad one panics inside zenoh."""
    depth = 0
    for ch in text:
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth < 0:
            break
    if not (text.strip().startswith("(") and text.strip().endswith(")") and depth == 0):
        raise ConfigError(f"ZENOH_RUNTIME={text!r} is not a zenoh runtime setting (e.g. {ONE_THREAD_RUNTIME})")


def open_session(net: NetConfig) -> zenoh.Session:
    """Open a zenoh session; use as `with open_session(net) as session:`."""
    OPENED[0] = True
    if os.environ.get("ZENOH_RUNTIME") in (None, ONE_THREAD_RUNTIME, CLIENT_RUNTIME):
        # Ours, not the user's (children inherit the launcher's environment): choose per mode.
        # A router relays to clients (a spectator on `**`): dropping for a slow one must not
        # hold the only thread that reads the peers' links.
        relays = net.mode in ("client", "router") or any(path == "access_control" for path, _ in net.extra)
        os.environ["ZENOH_RUNTIME"] = CLIENT_RUNTIME if relays else ONE_THREAD_RUNTIME
    check_runtime_variable(os.environ["ZENOH_RUNTIME"])
    for ep in net.listen:
        check_endpoint("--listen", ep)
    for ep in net.connect:
        check_endpoint("--connect", ep)
    try:
        return zenoh.open(net.zenoh_config())
    except zenoh.ZError as exc:
        where = " and ".join([*(f"listen on {e}" for e in net.listen), *(f"connect to {e}" for e in net.connect)])
        raise EndpointError(f"cannot {where or 'open a zenoh session'}: {zenoh_reason(exc)}") from None
    except (
        BaseException
    ) as exc:  # zenoh's Rust side panics (pyo3 PanicException, a BaseException) on a bad ZENOH_* variable
        if type(exc).__name__ != "PanicException":
            raise
        bad = [f"{k}={v}" for k, v in os.environ.items() if k.startswith("ZENOH_")]
        raise ConfigError(
            f"zenoh could not start ({zenoh_reason(exc)[:160]}); check the environment: {', '.join(bad) or 'no ZENOH_* set'}"
        ) from None
