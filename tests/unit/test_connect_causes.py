"""Issue 34: a router that listens but does not take a robot is named with its cause, and a robot's
stderr is `arena run:` lines only. The listeners here are real TLS and TCP servers on loopback."""

from __future__ import annotations

import io
import logging
import socket
import ssl
import threading

import pytest

from arena.match.connect import why_refused
from arena.match.run import configure_logging
from arena.runtime.credentials import Secrets


def _server(tls: tuple[bytes, bytes, bytes] | None, tmp_path):
    """A listener on a free loopback port that completes TLS handshakes (with `tls`) or just accepts."""
    srv = socket.create_server(("127.0.0.1", 0))
    ctx = None
    if tls is not None:
        (tmp_path / "c.pem").write_bytes(tls[1])
        (tmp_path / "k.pem").write_bytes(tls[2])
        ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
        ctx.load_cert_chain(tmp_path / "c.pem", tmp_path / "k.pem")

    def serve():
        while True:
            try:
                conn, _ = srv.accept()
            except OSError:
                return
            try:
                if ctx is not None:
                    conn = ctx.wrap_socket(conn, server_side=True)
                conn.recv(1)
            except (OSError, ssl.SSLError):
                pass
            conn.close()

    threading.Thread(target=serve, daemon=True).start()
    return srv, srv.getsockname()[1]


@pytest.fixture(scope="module")
def sets():
    names = ["engine", "robot/a/1"]
    return [Secrets.new("m", 1, names, secure=True, tls=True) for _ in range(2)]


def test_each_cause_is_its_own_line(sets, tmp_path):
    ours, theirs = sets
    srv, port = _server((ours.ca_pem, ours.router_cert_pem, ours.router_key_pem), tmp_path)
    plain, plain_port = _server(None, tmp_path)
    try:
        tls, tcp = f"tls/127.0.0.1:{port}", f"tcp/127.0.0.1:{port}"
        mine, other = ours.fragment("robot/a/1"), theirs.fragment("robot/a/1")
        said = {
            "no credentials": why_refused(tls, None, None, "robot-a-1"),
            "tcp to TLS": why_refused(tcp, None, None, "robot-a-1"),
            "another set": why_refused(tls, other, "old.json5", "robot-a-1"),
            "our CA, refused": why_refused(tls, mine, "a1.json5", "robot-a-1"),
            "tls to plain": why_refused(f"tls/127.0.0.1:{plain_port}", mine, "a1.json5", "robot-a-1"),
            "plain wants a password": why_refused(f"tcp/127.0.0.1:{plain_port}", None, None, "robot-a-1"),
        }
    finally:
        srv.close()
        plain.close()
    assert said["no credentials"].startswith(f"the router at {tls} is a secure match's: it needs this process's own")
    assert said["tcp to TLS"].startswith(f"the router at {tcp} speaks TLS (a secure match): connect to {tls}")
    assert "not signed by that file's CA (credentials of another match" in said["another set"]
    assert said["our CA, refused"].startswith(f"the router at {tls} refused robot-a-1's password from a1.json5")
    assert "does not speak TLS (not a secure match): connect to tcp/" in said["tls to plain"]
    assert "wants a user and password" in said["plain wants a password"]
    assert len(set(said.values())) == len(said) and not any("no router" in s for s in said.values())


def test_a_hand_started_process_logs_as_arena_run():
    out = io.StringIO()
    configure_logging("WARNING", by_hand=True, stream=out)
    try:
        logging.getLogger("arena.robot/a/1").warning("possible spoofing on %s", "arena/m/robot/a/1/sense")
    finally:
        configure_logging("WARNING", by_hand=False)
    assert out.getvalue() == "arena run: robot/a/1: warning: possible spoofing on arena/m/robot/a/1/sense\n"
