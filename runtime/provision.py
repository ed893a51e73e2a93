"""A credentials directory provisioned once: every principal's secret kept from match to match.

`arena match --credentials DIR`, `arena run router --credentials DIR` and `arena credentials
init DIR` keep what DIR already holds (the TLS CA, the router's certificate and key, every
principal's password and MAC key) and create only what is missing, so a robot's file copied
yesterday still works today, in any match that uses DIR, whatever its id. Only `arena
credentials rotate DIR` replaces secrets.

DIR holds, mode 0600 in a directory of mode 0700:

* `<user>.json5` for every principal (`robot-a-1.json5`, ..., `viewer.json5`): the complete
  fragment of a secure match (runtime/credentials.py), which a plain match accepts as well
  (`arena run` then connects without the password);
* `router.json5`: the CA and the router's certificate and private key (the CA's own key was
  dropped when it signed that certificate, so nobody can make another), the viewer's zenoh id
  and the set's id. It never leaves the machine that hosts the router.

Every file names the set's id (`metadata.arena.credentials`): files of two sets are never mixed.
"""

from __future__ import annotations

import json
import secrets
from pathlib import Path

from arena.config import ConfigError
from arena.runtime.acl import principals, user_of
from arena.runtime.credentials import Secrets, make_tls, new_zid, private_directory, write_private
from arena.runtime.mac import KEY_BYTES, new_key

ROUTER_FILE = "router.json5"
DAYS = 825  # the router certificate's validity: a season, not a match


def new_set_id() -> str:
    return secrets.token_hex(4)


def _read(path: Path) -> dict:
    try:
        data = json.loads(path.read_text())
    except OSError as exc:
        raise ConfigError(f"cannot read {path}: {exc.strerror}") from None
    except ValueError:
        raise ConfigError(f"{path} is not a credentials file (not JSON)") from None
    arena = data.get("metadata", {}).get("arena") if isinstance(data, dict) else None
    if not isinstance(arena, dict) or not isinstance(arena.get("process"), str):
        raise ConfigError(f"{path} has no metadata.arena.process: not a credentials file")
    return data


def _router_file(tls: tuple[bytes, bytes, bytes], viewer_zid: str, set_id: str) -> dict:
    ca, cert, key = (x.decode() for x in tls)
    arena = {"credentials": set_id, "process": "router", "ca": ca, "certificate": cert, "private_key": key}
    return {"metadata": {"arena": arena | {"viewer_id": viewer_zid}}}


def _is_credentials(path: Path) -> bool:
    try:
        _read(path)
    except ConfigError:
        return False
    return True


def _no_router(directory: Path, files: list[Path]) -> None:
    """ConfigError saying what is wrong with a directory that has .json5 files but no router.json5."""
    strangers = [p.name for p in files if not _is_credentials(p)]
    if strangers:
        raise ConfigError(
            f"{directory} holds {', '.join(strangers)}, which {'is' if len(strangers) == 1 else 'are'} not "
            f"a credentials file (no metadata.arena.process): move {'it' if len(strangers) == 1 else 'them'} "
            "out, or give a directory of its own to the credentials"
        )
    raise ConfigError(
        f"{directory} has credentials files but no {ROUTER_FILE} (the router's certificate): "
        f"run arena credentials rotate {directory} and copy every file again"
    )


def load(directory: Path) -> Secrets | None:
    """The set in `directory` (None if it holds none); ConfigError naming the file that is wrong."""
    router = directory / ROUTER_FILE
    files = sorted(p for p in directory.glob("*.json5") if p.name != ROUTER_FILE) if directory.is_dir() else []
    if not router.exists():
        if files:
            _no_router(directory, files)
        return None
    r = _read(router)["metadata"]["arena"]
    s = Secrets("", 0, [], secure=True, set_id=str(r.get("credentials", "")))
    try:
        s.ca_pem, s.router_cert_pem, s.router_key_pem = (r[k].encode() for k in ("ca", "certificate", "private_key"))
    except (KeyError, AttributeError):
        raise ConfigError(f"{router} lacks the CA, the certificate or the private key") from None
    s.viewer_zid = str(r.get("viewer_id") or new_zid())
    for path in files:
        data = _read(path)
        arena = data["metadata"]["arena"]
        p = arena["process"]
        if arena.get("credentials") != s.set_id:
            raise ConfigError(
                f"{path} belongs to credentials set {arena.get('credentials')!r}, {directory} to "
                f"{s.set_id!r}: remove it (it is created again) or use another directory"
            )
        try:
            password = data["transport"]["auth"]["usrpwd"]["password"]
            key = bytes.fromhex(arena["keys"][p])
        except (KeyError, TypeError, ValueError):
            raise ConfigError(f"{path} lacks {p}'s password or key: remove it (it is created again)") from None
        if len(key) != KEY_BYTES or not isinstance(password, str):
            raise ConfigError(f"{path}: {p}'s key is not {KEY_BYTES} bytes")
        s.passwords[p], s.mac_keys[p] = password, key
    return s


def provision(directory: Path, names: list[str], robots: int, match: str = "") -> tuple[Secrets, list[str]]:
    """Secrets for `names` (and the viewer) from `directory`, creating what is missing there.

    Returns (secrets, what was created or updated: file names). Files whose content would not
    change are not touched, so a robot's copy stays identical byte for byte."""
    private_directory(directory, create=True)
    s = load(directory)
    made: list[str] = []
    if s is None:
        s = Secrets("", 0, [], secure=True, set_id=new_set_id())
        s.ca_pem, s.router_cert_pem, s.router_key_pem = make_tls(days=DAYS)
        s.viewer_zid = new_zid()
        tls = (s.ca_pem, s.router_cert_pem, s.router_key_pem)
        write_private(directory / ROUTER_FILE, json.dumps(_router_file(tls, s.viewer_zid, s.set_id), indent=2) + "\n")
        made.append(ROUTER_FILE)
    s.match, s.secure = match, True
    s.processes = list(dict.fromkeys([*names, *(p for p in s.passwords if p not in names)]))
    for p in principals(s.processes):
        if p not in s.passwords:
            s.passwords[p], s.mac_keys[p] = secrets.token_urlsafe(24), new_key()
    # Each file holds the MAC keys of every sender its principal hears in a match of the set's
    # size, whatever this match's: a 3v3 match (or a rotation, robots=0) must not rewrite robot
    # a/4's file without the engine's key, which its copy on the robot needs in a 6v6 match.
    s.robots = max(robots, set_robots(s.passwords))
    for p in principals(s.processes):
        path = directory / f"{user_of(p)}.json5"
        text = json.dumps(s.fragment(p), indent=2) + "\n"
        if not path.exists() or path.read_text() != text:
            write_private(path, text)
            made.append(path.name)
    s.robots = robots  # the match's, for its access control
    return s, made


def set_robots(principals_of_set) -> int:
    """Robots per team a set provides for: one more than its highest robot number."""
    return max((int(p.rsplit("/", 1)[1]) + 1 for p in principals_of_set if p.startswith("robot/")), default=0)


def rotate(directory: Path, which: list[str]) -> list[str]:
    """New secrets for the principals `which` (all of them, the CA and the router's certificate too,
    if empty); returns the files written. Every rotated file must be copied again."""
    files = sorted(directory.glob("*.json5")) if directory.is_dir() else []
    if files and not (directory / ROUTER_FILE).exists() and not which:
        # The router's file is gone: everything is made anew, for the principals the files name.
        if not all(map(_is_credentials, files)):
            _no_router(directory, files)
        names = [_read(p)["metadata"]["arena"]["process"] for p in files]
        for p in files:
            p.unlink()
        return provision(directory, names, 0)[1]
    s = load(directory)
    if s is None:
        raise ConfigError(f"{directory} holds no credentials: arena credentials init {directory}")
    unknown = [p for p in which if p not in s.passwords]
    if unknown:
        raise ConfigError(f"{directory} has no credentials for {', '.join(unknown)} (it has: {', '.join(s.passwords)})")
    names = list(s.passwords)
    if not which:
        for p in directory.glob("*.json5"):
            p.unlink()
        return provision(directory, names, 0)[1]
    for p in dict.fromkeys(which):  # a principal named twice: its file was unlinked twice, the second failed
        (directory / f"{user_of(p)}.json5").unlink()
    return provision(directory, names, 0)[1]


def show(directory: Path) -> list[str]:
    """One line per file of the set in `directory`: what it is and who may read it."""
    s = load(directory)
    if s is None:
        raise ConfigError(f"{directory} holds no credentials: arena credentials init {directory}")
    from cryptography import x509

    ca = x509.load_pem_x509_certificate(s.ca_pem)
    cert = x509.load_pem_x509_certificate(s.router_cert_pem)
    lines = [
        f"credentials set {s.set_id} in {directory}",
        f"  {ROUTER_FILE}: the router's certificate, valid until {cert.not_valid_after_utc:%Y-%m-%d} "
        f"(CA {ca.fingerprint(ca.signature_hash_algorithm).hex()[:16]}); keep it on the router's machine",
    ]
    for p in s.passwords:
        path = directory / f"{user_of(p)}.json5"
        mode = path.stat().st_mode & 0o777
        warn = "" if mode & 0o077 == 0 else f" (mode {mode:o}: readable by others, chmod 600)"
        lines.append(f"  {path.name}: {p}{warn}")
    return lines
