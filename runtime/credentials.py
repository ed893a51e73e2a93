"""Per-match credentials: zenoh users and passwords, a per-event TLS CA, MAC keys.

`arena match` makes one `Secrets` per match and writes, for every principal,
one zenoh configuration fragment `<user>.json5` (schemas/README.md,
"Security"): everything a C, C++ or Rust client needs besides the router's
address. The file is plain JSON (valid JSON5), readable by the owner only:

    {"mode": "client",                                   # secure matches only
     "transport": {"auth": {"usrpwd": {"user": ..., "password": ...}},
                   "link": {"tls": {"root_ca_certificate_base64": ...,
                                    "verify_name_on_connect": false}}},
     "metadata": {"arena": {"credentials": ..., "process": ..., "keys": {process: hex}}}}

`metadata` is free-form in zenoh's configuration and stays local (zenoh shows
it only in the session's own admin space, off by default); `keys` holds the
process's own MAC key and the keys of the senders it verifies (runtime/mac.py);
`credentials` names the set the file belongs to: a fresh one per match, or a
directory provisioned once (runtime/provision.py), whose files work in every match.

Why clients through the router in secure mode: zenoh enforces access control
on the node that receives a message, by the user name its transport
authenticated. Between peers, each peer would have to hold every user's
password (to authenticate the others) and would enforce only its own ACL, and
a team's robot computer is not ours to trust. So every process is a client of
the router, which holds the only dictionary and the only ACL.

TLS: the CA is made fresh for every match, or once for a provisioned directory
(EC P-256, the `cryptography` package), signs exactly one certificate, the
router's, and its private key is dropped at once. A client that trusts only this CA can talk only to this
match's router, so the host name check adds nothing and is off (the router's
address is often an IP from a venue's DHCP).
"""

from __future__ import annotations

import base64
import datetime
import ipaddress
import json
import os
import secrets
from dataclasses import dataclass, field
from pathlib import Path

from arena.runtime.acl import COLLECTOR_PRINCIPAL, VIEWER, access_control, principals, user_of
from arena.schemas.keys import routes

__all__ = [
    "COLLECTOR_PRINCIPAL",
    "Secrets",
    "load_fragment",
    "loopback_only",
    "make_tls",
    "private_directory",
    "secure_endpoint",
    "write_private",
]
from arena.runtime.mac import Keyring, new_key

# Besides the senders of every key it receives (the key table, `routes`): the keys outside the table.
# The engine takes a live session's `control` from the viewer and `operator` frames from the
# operator, the referee the `operator` frames; a process started by hand asks the engine for the
# `config` (every principal already verifies the engine: its `field` goes to all).
ALSO_VERIFIES = {
    "viewer": ["engine", "referee"],
    "engine": ["viewer", "operator"],
    "referee": ["operator"],
    "refbox": ["engine"],
}


def new_zid() -> str:
    """A zenoh id chosen before its session starts, so others can name it (32 hex digits, no leading 0)."""
    return f"{secrets.randbits(127) | 1 << 126:x}"


def drop_puts_towards(name: str, zid: str) -> list[dict]:
    """A zenoh `qos/network` setting: puts this session sends to the session `zid` are DROP."""
    rule = {"id": name, "zids": [zid], "messages": ["put"], "flows": ["egress"]}
    return [rule | {"overwrite": {"congestion_control": "drop"}}]


@dataclass
class Secrets:
    match: str
    robots: int
    processes: list[str]  # MatchConfig.processes(), as names
    secure: bool
    passwords: dict[str, str] = field(default_factory=dict)
    mac_keys: dict[str, bytes] = field(default_factory=dict)
    ca_pem: bytes = b""
    router_cert_pem: bytes = b""
    router_key_pem: bytes = b""
    viewer_zid: str = ""  # secure: the viewer's zenoh id, which the router serves with DROP
    set_id: str = field(default_factory=lambda: secrets.token_hex(4))  # metadata.arena.credentials

    @classmethod
    def new(cls, match: str, robots: int, processes: list[str], secure: bool, tls: bool = False) -> Secrets:
        s = cls(match, robots, list(processes), secure)
        for p in principals(s.processes):
            s.passwords[p] = secrets.token_urlsafe(24)
            s.mac_keys[p] = new_key()
        if tls:
            s.ca_pem, s.router_cert_pem, s.router_key_pem = make_tls()
        if secure:
            s.viewer_zid = new_zid()
        return s

    def keyring(self, principal: str, lent: tuple[str, ...] = ()) -> Keyring:
        """The keys `principal` holds: its own, its senders'; `lent`: other principals' it may sign as."""
        if principal in ("recorder", "launcher", COLLECTOR_PRINCIPAL):
            verifies = list(self.mac_keys)
        else:  # every frame it receives carries its sender's MAC (runtime/mac.py)
            senders = [s for _, s, receivers in routes(self.robots) if principal in receivers]
            verifies = [principal, *senders, *ALSO_VERIFIES.get(principal, []), *lent]
        return Keyring(principal, {p: self.mac_keys[p] for p in verifies if p in self.mac_keys})

    def fragment(self, principal: str, lent: tuple[str, ...] = ()) -> dict:
        ring = self.keyring(principal, lent)
        frag: dict = {}
        if self.secure:
            frag["mode"] = "client"
            usrpwd = {"user": user_of(principal), "password": self.passwords[principal]}
            frag["transport"] = {"auth": {"usrpwd": usrpwd}}
            if self.ca_pem:
                tls = {"root_ca_certificate_base64": base64.b64encode(self.ca_pem).decode()}
                frag["transport"]["link"] = {"tls": tls | {"verify_name_on_connect": False}}
            if principal == VIEWER and self.viewer_zid:
                frag["id"] = self.viewer_zid  # `router_settings`: the router serves this id with DROP
        keys = {p: k.hex() for p, k in sorted(ring.keys.items())}
        frag["metadata"] = {"arena": {"credentials": self.set_id, "process": principal, "keys": keys}}
        return frag

    def write(
        self,
        directory: Path,
        more: dict[str, dict] | None = None,
        launched=(),
        lend: dict[str, tuple[str, ...]] | None = None,
    ) -> dict[str, Path]:
        """Write every principal's fragment (mode 0600) into `directory`; returns their paths.

        `more`: zenoh settings added to some principals' fragments (top-level keys),
        e.g. the launcher's own peers' `qos` (match/launcher.py, `relay_safe`).
        `launched`: the principals `arena match` starts itself, whose identity it holds for them
        (`metadata.arena.launched`; the match gives them their identity by OS pid, match/claims.py).
        `lend`: principal -> the other principals whose keys its fragment holds too (the live viewer
        of a local operator gets the operator's, match/launcher.py)."""
        private_directory(directory, create=True)
        out = {}
        for p in principals(self.processes):
            path = directory / f"{user_of(p)}.json5"
            frag = self.fragment(p, (lend or {}).get(p, ())) | (more or {}).get(p, {})
            if p in launched:
                frag["metadata"]["arena"]["launched"] = True
            write_private(path, json.dumps(frag, indent=2) + "\n")
            out[p] = path
        return out

    def router_settings(self, directory: Path) -> list[tuple[str, str]]:
        """(json5 path, json5 value) for the router's zenoh configuration (secure matches)."""
        dictionary = directory / "router-users.txt"
        write_private(dictionary, "".join(f"{user_of(p)}:{pw}\n" for p, pw in self.passwords.items()))
        acl = access_control(f"arena/{self.match}/", self.robots, self.processes)
        items = [
            ("transport/auth/usrpwd/dictionary_file", json.dumps(str(dictionary))),
            ("access_control", json.dumps(acl)),
        ]
        if self.viewer_zid:
            # Every process of a secure match is a client and every frame goes through the router
            # with its sender's QoS (BLOCK), so a viewer reading slowly held the router on its queue
            # and paced the whole match (a 5 ms-per-sample viewer: about 8 s instead of 3 s). The
            # viewer is the one principal nobody waits for: what the router puts towards it is DROP.
            # One viewer per credentials file at a time: zenoh refuses a second session with that id.
            items.append(("qos/network", json.dumps(drop_puts_towards("viewer", self.viewer_zid))))
        if self.router_cert_pem:
            for name, pem in (
                ("listen_certificate", self.router_cert_pem),
                ("listen_private_key", self.router_key_pem),
            ):
                items.append((f"transport/link/tls/{name}_base64", json.dumps(base64.b64encode(pem).decode())))
        return items


def loopback_only(endpoint: str | None) -> bool:
    """True for a unix socket or a TCP/TLS/UDP/QUIC endpoint on a loopback address."""
    if endpoint is None or endpoint.startswith("unixsock-stream/"):
        return True
    address = endpoint.split("/", 1)[-1].split("#", 1)[0]
    host = address.rsplit(":", 1)[0].strip("[]")
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False  # a host name: assume it is reachable from elsewhere


def secure_endpoint(endpoint: str) -> tuple[str, bool]:
    """The endpoint a secure match listens on (tcp becomes tls) and whether it uses TLS."""
    proto, _, rest = endpoint.partition("/")
    if proto == "tcp":
        return "tls/" + rest, True
    return endpoint, proto in ("tls", "quic")


def write_private(path: Path, text: str) -> None:
    """Mode 0600, and whole or not at all (a process may be waiting to read it).

    Written to a new file of a random name (O_EXCL | O_NOFOLLOW: a file or symlink put there
    beforehand makes it fail, never redirects it) and renamed over `path` (which replaces a
    symlink at `path` instead of following it)."""
    part = path.with_name(f".{path.name}.{secrets.token_hex(8)}.part")
    fd = os.open(part, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(part, path)
    except BaseException:
        part.unlink(missing_ok=True)
        raise


def private_directory(directory: Path, create: bool = False) -> None:
    """`directory` must be ours and writable by nobody else (mode 0700 when made here); ConfigError if not."""
    from arena.config import ConfigError

    try:
        if create and not directory.exists():
            directory.mkdir(parents=True, mode=0o700)
        st = os.lstat(directory)
    except OSError as exc:
        raise ConfigError(f"cannot make credentials directory {directory}: {exc.strerror}") from None
    import stat

    if not stat.S_ISDIR(st.st_mode):
        raise ConfigError(f"credentials directory {directory} is not a directory (or is a symlink)")
    if st.st_uid != os.getuid() or st.st_mode & 0o022:
        raise ConfigError(
            f"credentials directory {directory} is writable by others or not yours: chmod 700 it, or use another"
        )


OWNER = "owner"  # in a match's temp dir: "<pid> <start time>" of the process that made it


def _started(pid: int) -> str:
    """The start time of process `pid` (Linux: /proc), to tell it from a later one with its pid."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError):
        return ""


def match_directory(prefix: str = "arena-") -> Path:
    """A private temp dir for one match's secrets, sockets and logs, marked with its owner.

    Its maker removes it on every exit it survives; `sweep` removes those of makers that were
    killed (kill -9, power loss), so no password outlives the next start."""
    import tempfile

    sweep(prefix)
    tmp = Path(tempfile.mkdtemp(prefix=prefix))
    (tmp / OWNER).write_text(f"{os.getpid()} {_started(os.getpid())}\n")
    return tmp


def sweep(prefix: str = "arena-") -> list[Path]:
    """Remove the temp dirs `match_directory` made for processes that no longer exist; returns them."""
    import shutil
    import tempfile

    gone = []
    for d in Path(tempfile.gettempdir()).glob(prefix + "*"):
        try:
            if d.is_symlink() or d.stat().st_uid != os.getuid():
                continue
            pid_text, _, started = (d / OWNER).read_text().strip().partition(" ")
            pid = int(pid_text)
        except (OSError, ValueError):
            continue  # not made by match_directory
        if Path(f"/proc/{pid}").exists() and _started(pid) == started:
            continue
        if not Path("/proc/self").exists():
            try:
                os.kill(pid, 0)
                continue
            except ProcessLookupError:
                pass
            except PermissionError:
                continue
        shutil.rmtree(d, ignore_errors=True)
        gone.append(d)
    return gone


def load_fragment(path: str) -> dict:
    """A credentials fragment written by `arena match`; ValueError with a one-line reason if unusable."""
    try:
        data = json.loads(Path(path).read_text())
    except OSError as exc:
        raise ValueError(f"cannot read --credentials {path}: {exc.strerror}") from None
    except ValueError:
        raise ValueError(f"--credentials {path} is not a credentials file written by arena match") from None
    arena = data.get("metadata", {}).get("arena") if isinstance(data, dict) else None
    if not isinstance(arena, dict) or not isinstance(arena.get("process"), str):
        raise ValueError(f"--credentials {path} has no metadata.arena.process: not written by arena match")
    return data


def make_tls(hosts: tuple[str, ...] = ("127.0.0.1", "localhost"), days: int = 2) -> tuple[bytes, bytes, bytes]:
    """A fresh CA and the router's certificate signed by it: (ca_pem, cert_pem, key_pem)."""
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import NameOID

    now = datetime.datetime.now(datetime.UTC)
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, f"arena match CA {secrets.token_hex(4)}")])
    ca = (
        x509.CertificateBuilder()
        .subject_name(ca_name)
        .issuer_name(ca_name)
        .public_key(ca_key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=days))
        .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
        .sign(ca_key, hashes.SHA256())
    )
    key = ec.generate_private_key(ec.SECP256R1())
    names: list[x509.GeneralName] = []
    for h in hosts:
        try:
            names.append(x509.IPAddress(ipaddress.ip_address(h)))
        except ValueError:
            names.append(x509.DNSName(h))
    cert = (
        x509.CertificateBuilder()
        .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "arena router")]))
        .issuer_name(ca_name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=days))
        .add_extension(x509.SubjectAlternativeName(names), critical=False)
        .sign(ca_key, hashes.SHA256())
    )
    pem = serialization.Encoding.PEM
    key_pem = key.private_bytes(pem, serialization.PrivateFormat.PKCS8, serialization.NoEncryption())
    return ca.public_bytes(pem), cert.public_bytes(pem), key_pem
