"""Why a router that listens did not take us: one line naming the cause.

zenoh reports every failed connect as "Unable to connect". When something does listen at
the endpoint (`session.listening`), a TLS handshake of our own, outside zenoh, tells the
causes apart:

* the router speaks TLS and we came without credentials, or over `tcp/`;
* it speaks TLS, but its certificate is not signed by the CA in our credentials file: the
  file is another match's, or another credentials directory's;
* its certificate is signed by our CA, so it refused our password: the file was rotated
  since it was copied;
* it does not speak TLS and we asked for `tls/`, or it wants a password we do not have.
"""

from __future__ import annotations

import socket
import ssl


def _host_port(endpoint: str) -> tuple[str, int] | None:
    proto, _, address = endpoint.partition("/")
    if proto not in ("tcp", "tls"):
        return None
    host, _, port = address.split("?", 1)[0].split("#", 1)[0].rpartition(":")
    try:
        return host.strip("[]"), int(port)
    except ValueError:
        return None


def handshake(endpoint: str, ca_pem: bytes | None = None, timeout: float = 2.0) -> bool | None:
    """Does the listener at `endpoint` complete a TLS handshake (verified against `ca_pem` if given)?
    None if it cannot be asked (not TCP, or nothing there)."""
    hp = _host_port(endpoint)
    if hp is None:
        return None
    ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    ctx.check_hostname = False  # as zenoh's clients here: the CA signs only the router's certificate
    if ca_pem is None:
        ctx.verify_mode = ssl.CERT_NONE
    else:
        ctx.load_verify_locations(cadata=ca_pem.decode())
    try:
        raw = socket.create_connection(hp, timeout=timeout)
    except OSError:
        return None
    try:
        with ctx.wrap_socket(raw) as tls:
            tls.do_handshake()
            return True
    except OSError:  # ssl.SSLError included: it answered, but not with TLS we trust (or hung up)
        return False
    finally:
        raw.close()


def ca_of(fragment: dict | None) -> bytes | None:
    import base64

    try:
        return base64.b64decode(fragment["transport"]["link"]["tls"]["root_ca_certificate_base64"])  # type: ignore[index]
    except (KeyError, TypeError, ValueError):
        return None


def has_password(fragment: dict | None) -> bool:
    try:
        return bool(fragment["transport"]["auth"]["usrpwd"]["password"])  # type: ignore[index]
    except (KeyError, TypeError):
        return False


def why_refused(endpoint: str, fragment: dict | None, path: str | None, user: str) -> str:
    """The cause, as one line, of a router at `endpoint` that listens but did not take this session."""
    proto, _, address = endpoint.partition("/")
    ca = ca_of(fragment)
    own = f"this process's own --credentials file ({user}.json5, written by arena match --credentials DIR)"
    tls = handshake(endpoint) if proto in ("tcp", "tls") else None
    if tls:
        if proto == "tcp":
            return f"the router at {endpoint} speaks TLS (a secure match): connect to tls/{address} with {own}"
        if ca is None:
            return f"the router at {endpoint} is a secure match's: it needs {own}"
        if not handshake(endpoint, ca):
            return (
                f"the router at {endpoint} is not the one {path} is for: its TLS certificate is not signed by "
                f"that file's CA (credentials of another match or credentials directory: copy {user}.json5 "
                "again from the directory this match uses)"
            )
        return (
            f"the router at {endpoint} refused {user}'s password from {path}: the match's credentials were "
            f"rotated since the file was copied (copy {user}.json5 again)"
        )
    if proto == "tls" and tls is False:
        return f"the router at {endpoint} does not speak TLS (not a secure match): connect to tcp/{address}"
    if not has_password(fragment):
        return f"refused by {endpoint}: the router wants a user and password (a secure match): it needs {own}"
    return f"refused by {endpoint}: authentication failed ({user}'s password from {path} is not this match's)"
