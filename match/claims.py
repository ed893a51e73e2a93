"""One identity, one process: the match's router gives each process identity to one claimant.

A process started by hand (`arena run`) first declares a liveliness token
`arena/<m>/claim/<process>/<nonce>` and then asks `arena/<m>/claim/<process>` with its nonce,
host, pid and, if it has credentials, a MAC of the nonce under its own key (runtime/mac.py).
The router's host (`arena match`, `arena run router`) answers one claim at a time, and only
once the claimant's token has reached it, so of two processes started at the same moment
exactly one gets the identity, in either mode; the other is refused with the reason. The identity is free again when the
holder's token vanishes (it exited or its session was lost). `arena match` holds its own
processes' identities from the start and gives each only to the process it started (by OS
pid): a second process with one of their credentials files is refused like any other.

The same answer refuses a process whose credentials cannot be this match's: no key where
the match has one for that process (it left out `--credentials`), or a key that does not
verify (a file of another match or credentials directory). Without this, such a process
played on and every frame it sent was dropped as forged.
"""

from __future__ import annotations

import json
import os
import secrets
import socket
import threading
import time

import zenoh

from arena.config import ConfigError, ProcessId
from arena.runtime.mac import Keyring
from arena.schemas.keys import Keys

TOKEN_WAIT = 2.0  # [s] a claim whose token has not reached the router by then is refused


def _text(payload: bytes) -> dict:
    try:
        data = json.loads(payload)
    except ValueError:
        return {}
    return data if isinstance(data, dict) else {}


class Claims:
    """The router side: who holds which identity of match `keys.match`."""

    def __init__(
        self, session, keys: Keys, keyring: Keyring | None, reserved: dict[str, str], announce=None, pid_of=None
    ):
        """`reserved`: identities held from the start (process -> by whom); `pid_of(process)`: the
        OS pid of the process `arena match` started for a reserved identity, which alone may claim it
        (this host's pid of a running child: no second process has it)."""
        self.keys = keys
        self.pid_of = pid_of or (lambda process: None)
        self.keyring = keyring
        self.announce = announce or (lambda text: None)
        self.refused: list[dict] = []  # every refusal, for the match's JSON
        self._lock = threading.Condition()
        self._held: dict[str, dict] = {p: {"nonce": None, "who": who} for p, who in reserved.items()}
        self._tokens: set[str] = set()  # "<process>/<nonce>" with a live token
        prefix = keys.claim("")
        self._prefix = prefix
        self._sub = session.liveliness().declare_subscriber(keys.claim_all(), self._on_token, history=True)
        self._queryable = session.declare_queryable(keys.claim_all())
        self._thread = threading.Thread(target=self._serve, name="claims", daemon=True)
        self._thread.start()

    def _on_token(self, sample: zenoh.Sample) -> None:
        token = str(sample.key_expr)[len(self._prefix) :]
        with self._lock:
            if sample.kind == zenoh.SampleKind.PUT:
                self._tokens.add(token)
            else:
                self._tokens.discard(token)
                process, _, nonce = token.rpartition("/")
                if self._held.get(process, {}).get("nonce") == nonce:
                    del self._held[process]  # its holder is gone: the identity is free again
            self._lock.notify_all()

    def _serve(self) -> None:
        for query in self._queryable:  # ends when the queryable is undeclared
            with query:
                process = str(query.key_expr)[len(self._prefix) :]
                claim = _text(query.payload.to_bytes() if query.payload is not None else b"")
                reason = self.decide(process, claim)
                query.reply(query.key_expr, json.dumps({"ok": reason is None, "reason": reason}).encode())

    def decide(self, process: str, claim: dict) -> str | None:
        """None: `process` is the claimant's now; else why it is refused."""
        nonce = str(claim.get("nonce", ""))
        who = f"from {claim.get('host', '?')}, pid {claim.get('pid', '?')}"
        deadline = time.monotonic() + TOKEN_WAIT
        with self._lock:
            while f"{process}/{nonce}" not in self._tokens and time.monotonic() < deadline:
                self._lock.wait(0.05)
            held = self._held.get(process)
            if held is not None and held["nonce"] is None and self._own_child(process, claim):
                held = None  # arena match's own process for this identity, claiming what it was kept for
                who = f"started by arena match, pid {claim.get('pid')}"
            if held is not None and held["nonce"] != nonce:
                reason: str | None = (
                    f"{process} is already running in match {self.keys.match!r} ({held['who']}): "
                    "a second one is refused (check --team and --robot)"
                )
            elif f"{process}/{nonce}" not in self._tokens:
                reason = f"its claim token did not reach the router within {TOKEN_WAIT:g} s"
            else:
                reason = self._check_key(process, nonce, claim.get("mac"))
            if reason is None:
                self._held[process] = {"nonce": nonce, "who": who}
        if reason is not None:
            self.refused.append({"process": process, "from": who.removeprefix("from "), "reason": reason})
            self.announce(f"refused {process} {who}: {reason}")
        return reason

    def _own_child(self, process: str, claim: dict) -> bool:
        pid = self.pid_of(process)
        return pid is not None and claim.get("pid") == pid and claim.get("host") == socket.gethostname()

    def _check_key(self, process: str, nonce: str, mac) -> str | None:
        verify = self.keyring.verifier(process, self.keys.claim(process)) if self.keyring is not None else None
        if verify is None:
            return None  # no key for it here: any claimant may have it
        if not mac:
            return (
                f"match {self.keys.match!r} needs {process}'s own --credentials file (every frame of its "
                "processes is authenticated): start it with the command arena match printed"
            )
        try:
            tag = bytes.fromhex(str(mac))
        except ValueError:
            tag = b""
        if not verify(nonce.encode(), tag):
            return (
                f"the key in {process}'s --credentials file is not this match's (a file of another match "
                "or credentials directory): copy it again from the directory this match uses"
            )
        return None

    def close(self) -> None:
        self._sub.undeclare()
        self._queryable.undeclare()
        self._thread.join(timeout=2.0)


# ---------------------------------------------------------------- the claimant's side (`arena run`)
def claim(session, keys: Keys, pid: ProcessId, keyring: Keyring | None, timeout: float = 3.0):
    """Ask the match's router for this identity (match/claims.py); ConfigError with the
    router's reason if refused. Returns the liveliness token that holds it (keep it while running),
    or None if nobody answers (a router that gives out no identities)."""
    name = str(pid)
    nonce = secrets.token_hex(8)
    token = session.liveliness().declare_token(keys.claim_token(name, nonce))
    sign = keyring.signer(keys.claim(name)) if keyring is not None else None
    ask = {"nonce": nonce, "host": socket.gethostname(), "pid": os.getpid()}
    if sign is not None:
        ask["mac"] = sign(nonce.encode()).hex()
    for reply in session.get(keys.claim(name), payload=json.dumps(ask).encode(), timeout=timeout):
        if reply.ok is None:
            continue
        try:
            answer = json.loads(reply.ok.payload.to_bytes())
        except ValueError:
            continue
        if answer.get("ok"):
            return token
        token.undeclare()
        raise ConfigError(f"refused by match {keys.match!r}: {answer.get('reason')}")
    token.undeclare()
    return None


def hold_identity(session, keys: Keys, pid: ProcessId, keyring: Keyring | None):
    """This process's identity in the match, or ConfigError with the reason it is someone else's.
    `arena match` holds its own processes' for them; a router that gives out none leaves the
    liveliness check. Returns what holds it (None: nothing to keep).

    A credentials file that says `launched` (one of `arena match`'s own, from its private temp
    dir) proves nothing about who holds it: its holder claims the identity as any other process,
    and the match gives it only to the process it started (by OS pid, `Claims.pid_of`). A second
    process started with that file, by hand or with the match's own `--config`, is refused."""
    held = claim(session, keys, pid, keyring)
    if held is None:
        refuse_duplicate(session, keys, pid)
    return held


def refuse_duplicate(session, keys: Keys, pid: ProcessId) -> None:
    """Liveliness knows who is there: a second process with a running one's identity is turned away.

    The match hears of it too (`arena/<m>/refused/<process>`, printed by `arena match`).
    """
    name = str(pid)
    if not any(r.ok is not None for r in session.liveliness().get(keys.alive(name), timeout=1.0)):
        return
    session.put(keys.refused(name), f"{socket.gethostname()}, pid {os.getpid()}".encode())
    time.sleep(0.2)  # let the put leave before the session closes
    raise ConfigError(
        f"{name} is already running in match {keys.match!r}: a second one is refused (check --team and --robot)"
    )
