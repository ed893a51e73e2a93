"""The MSL RefBox wire protocol, both generations, as pure functions and small readers.

Sources (read with the RoboCup-MSL/RefBox repository and a KRSBI-B base station):
* 2020 JSON protocol, RoboCup-MSL/RefBox `mslrb2015/Comms.pde`
  (`send_to_basestation`): one JSON object `{"command": C, "targetTeam": T}`
  (plus `"robotID": n` for the robot commands) followed by a NUL byte, no
  length prefix. The same bytes go to every connected base station; a team
  filters on `targetTeam`, its `MulticastAddr` in `mslrb2015/data/msl_teams.json`,
  and an empty `targetTeam` means both teams. The 30 command names are the
  `COMM_*` constants of the same file (plus IS_ALIVE).
* Team identification, `setteamfromip` in `mslrb2015/Comms.pde`: the client's
  IPv4 address cut to `a.b.c.*` and compared with `UnicastAddr`; IPv6 `::1`
  counts as `127.0.0.*`. An unknown team gets RESET and is disconnected.
* Worldstate validation, `checkBasestationsMessages` in `mslrb2015/Comms.pde`
  and the schema in `tools/JSON Worldstate Validator/MSLWMD-schema`:
  NUL-terminated JSON; required keys `type` (= "worldstate"), `ageMs` (a
  number), `teamName`, `intention` (strings), `robots`, `balls`, `obstacles`
  (arrays); a message that is still not terminated after 100,000 characters is
  discarded. A bad message is logged; the team gets no reply.
* The legacy one-character protocol (before 2020), RoboCup-MSL/RefBox
  `RefereeClient/Comms.pde` and the KRSBI-B translator of
  Tim-KRSBI-Beroda-UM/basesation-legacy (`translator.py`): one byte per
  command, no terminator; team commands are upper case for cyan and lower case
  for magenta (`K`/`k` kick-off), `s` START, `S` STOP, `1`/`2` halves, `h` half
  time, `e` end game, `N` drop ball, `L` park, `W` welcome, `Z` reset.

Our match's teams are "a" and "b"; by default a is cyan and b magenta
(`swap` turns that round).
"""

from __future__ import annotations

import ipaddress
import json
import math
from collections.abc import Iterable
from dataclasses import dataclass

from arena.config import ConfigError
from arena.config import RefboxTeam as TeamEntry
from arena.runtime.userfile import json_nesting

PORT = 28097  # the RefBox's base-station port
MAX_UNTERMINATED = 100_000  # [characters] the RefBox discards a message this long without its NUL
# [levels] arrays and objects inside one another in a worldstate at most (the schema's deepest is 4:
# robots, a robot, its pose, a number). Deeper is refused unparsed (`too-deep`): Python's JSON
# parser recurses, and 2,000 `[` raised RecursionError, which killed the bridge's server thread.
MAX_DEPTH = 32
LOG_FIRST_ERRORS = 20  # bad messages of one connection logged one by one; the rest are counted only

COMMANDS = (
    "START", "STOP", "WELCOME", "RESET", "TESTMODE_ON", "TESTMODE_OFF",
    "FIRST_HALF", "SECOND_HALF", "FIRST_HALF_OVERTIME", "SECOND_HALF_OVERTIME",
    "HALF_TIME", "END_GAME", "END_PART", "GAMEOVER", "PARK",
    "YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW",
    "GOAL", "SUBGOAL",
    "KICKOFF", "FREEKICK", "GOALKICK", "THROWIN", "CORNER", "PENALTY", "DROP_BALL",
    "REPAIR", "SUBSTITUTION", "IS_ALIVE",
)  # fmt: skip
# Commands whose targetTeam names a team; every other command goes with "".
TEAM_COMMANDS = frozenset(
    {"KICKOFF", "FREEKICK", "GOALKICK", "THROWIN", "CORNER", "PENALTY", "GOAL", "SUBGOAL"}
    | {"YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW", "REPAIR", "SUBSTITUTION", "IS_ALIVE"}
)
# Carry robotID: the RefBox's IS_ALIVE and SUBSTITUTION, and our referee's cards and REPAIR,
# which name the robot they are about (a client that does not know the key ignores it).
ROBOT_COMMANDS = frozenset({"IS_ALIVE", "SUBSTITUTION", "YELLOW_CARD", "RED_CARD", "DOUBLE_YELLOW", "REPAIR"})
# Our command names (schemas/vocabulary.py) that the 2020 protocol spells differently, both ways.
OUR_TO_WIRE = {"REPAIR_OUT": "REPAIR"}
WIRE_TO_OURS = {w: o for o, w in OUR_TO_WIRE.items()}

# Legacy characters: team commands as the cyan (upper case) letter, the others as is.
LEGACY_TEAM = {
    "KICKOFF": "K", "FREEKICK": "F", "GOALKICK": "G", "THROWIN": "T", "CORNER": "C", "PENALTY": "P",
    "GOAL": "A", "SUBGOAL": "D", "REPAIR": "O", "RED_CARD": "R", "YELLOW_CARD": "Y", "DOUBLE_YELLOW": "B",
}  # fmt: skip
LEGACY_COMMON = {
    "STOP": "S", "START": "s", "WELCOME": "W", "RESET": "Z", "TESTMODE_ON": "U", "TESTMODE_OFF": "u",
    "FIRST_HALF": "1", "SECOND_HALF": "2", "FIRST_HALF_OVERTIME": "3", "SECOND_HALF_OVERTIME": "4",
    "HALF_TIME": "h", "END_GAME": "e", "GAMEOVER": "z", "PARK": "L", "DROP_BALL": "N",
}  # fmt: skip
# Character -> (command, colour or "").
LEGACY_DECODE = {c: (name, "") for name, c in LEGACY_COMMON.items()} | {
    c: (name, colour) for name, up in LEGACY_TEAM.items() for c, colour in ((up, "cyan"), (up.lower(), "magenta"))
}
PROTOCOLS = ("json", "legacy")
COLOURS = ("cyan", "magenta")
DEFAULT_TARGETS = {"cyan": "224.16.32.201", "magenta": "224.16.32.202"}  # no MSL team uses these


class ProtocolError(ConfigError):
    """A value that cannot be used (an endpoint, a team table); the message is one line."""


# ------------------------------------------------------------------ sides
def colour_of(team: str, swap: bool = False) -> str:
    """Our team ("a"/"b") -> RefBox colour: a is cyan unless `swap`."""
    return ("magenta" if team == "a" else "cyan") if swap else ("cyan" if team == "a" else "magenta")


def team_of(colour: str, swap: bool = False) -> str:
    return ("b" if colour == "cyan" else "a") if swap else ("a" if colour == "cyan" else "b")


# --------------------------------------------------------------- commands
def encode_json(command: str, target: str = "", robot_id: int | None = None) -> bytes:
    """One 2020 command: a JSON object and its NUL."""
    obj: dict[str, object] = {"command": command, "targetTeam": target}
    if robot_id is not None and command in ROBOT_COMMANDS:
        obj["robotID"] = robot_id
    return json.dumps(obj, separators=(",", ":")).encode() + b"\0"


def encode_legacy(command: str, colour: str = "") -> bytes | None:
    """One legacy command byte, or None when the legacy protocol has no character for it."""
    if command in LEGACY_TEAM:
        if colour not in COLOURS:
            return None
        c = LEGACY_TEAM[command]
        return (c if colour == "cyan" else c.lower()).encode()
    c = LEGACY_COMMON.get(command)
    return c.encode() if c else None


@dataclass(frozen=True)
class Command:
    """A command as a base station receives it: name, targetTeam (JSON) or colour (legacy)."""

    name: str
    target: str = ""
    colour: str = ""
    robot_id: int = -1


class CommandReader:
    """The base-station side: bytes in, `Command`s out, in either framing.

    A message that starts with `{` is JSON up to its NUL; any other byte is a
    legacy character. Unknown or malformed ones are returned in `errors`, the
    first `LOG_FIRST_ERRORS` of a connection one by one and the rest only counted
    in `dropped`. Linear in what arrives: every byte is looked at once, however
    the stream is cut.
    """

    def __init__(self) -> None:
        self._buf = bytearray()
        self._scanned = 0  # bytes of an unterminated JSON command already searched for its NUL
        self._skipping = False  # inside an overlong JSON command: drop up to its NUL
        self.errors: list[str] = []
        self.dropped = 0  # errors beyond the first LOG_FIRST_ERRORS
        self._logged = 0

    def _error(self, why: str) -> None:
        if self._logged < LOG_FIRST_ERRORS:
            self._logged += 1
            self.errors.append(why)
        else:
            self.dropped += 1

    def feed(self, data: bytes) -> list[Command]:
        self._buf += data
        buf, out, i = self._buf, [], 0
        while i < len(buf):
            if self._skipping or buf[i] == 0x7B:  # "{": a JSON command up to its NUL
                end = buf.find(b"\0", max(i, self._scanned))
                if end < 0:
                    if len(buf) - i > MAX_UNTERMINATED and not self._skipping:
                        self._error(f"command not terminated within {MAX_UNTERMINATED} bytes")
                        self._skipping = True
                    if self._skipping:
                        i = len(buf)
                    self._scanned = len(buf)
                    break
                if self._skipping:
                    self._skipping = False
                elif end - i > MAX_UNTERMINATED:
                    self._error(f"command not terminated within {MAX_UNTERMINATED} bytes")
                else:
                    cmd = _json_command(bytes(buf[i:end]))
                    if isinstance(cmd, str):
                        self._error(cmd)
                    else:
                        out.append(cmd)
                i = end + 1
            else:
                ch = chr(buf[i])
                i += 1
                if ch in "\0\n\r ":
                    continue
                if ch in LEGACY_DECODE:
                    name, colour = LEGACY_DECODE[ch]
                    out.append(Command(name, colour=colour))
                else:
                    self._error(f"unknown legacy command {ch!r}")
        del buf[:i]
        self._scanned = max(0, self._scanned - i)
        return out


def _json_command(raw: bytes) -> Command | str:
    text = raw.decode("utf-8", errors="replace")
    if nesting(text) > MAX_DEPTH:
        return f"JSON command nested deeper than {MAX_DEPTH} levels"
    try:
        obj = json.loads(text)
    except ValueError:
        return "malformed JSON command"
    if not isinstance(obj, dict) or not isinstance(obj.get("command"), str):
        return "JSON command without a command name"
    name, target = obj["command"], obj.get("targetTeam", "")
    if name not in COMMANDS:
        return f"unknown command {name!r}"
    rid = obj.get("robotID", -1)
    return Command(name, target=target if isinstance(target, str) else "", robot_id=rid if type(rid) is int else -1)


# -------------------------------------------------------------- worldstate
REQUIRED_STRINGS = ("teamName", "intention")
REQUIRED_ARRAYS = ("robots", "balls", "obstacles")


@dataclass(frozen=True)
class WorldstateResult:
    """One message off a base station's socket: `doc` when valid, else `reason` and `detail`."""

    raw: str
    doc: dict | None = None
    reason: str = ""  # malformed-json | missing-key | wrong-type | not-terminated | too-deep
    detail: str = ""


def nesting(raw: str) -> int:
    """How deep arrays and objects nest in `raw` (JSON text), brackets inside strings not counted;
    linear in its length whatever it holds, no regular expression (`userfile.json_nesting`)."""
    return json_nesting(raw)


def validate_worldstate(raw: str) -> WorldstateResult:
    """The RefBox's checks, in its order; the first failure is the reason. Before them, our own
    bound: nesting deeper than `MAX_DEPTH` is `too-deep`, never parsed."""
    deep = nesting(raw)
    if deep > MAX_DEPTH:
        return WorldstateResult(raw[:60], reason="too-deep", detail=f"{deep} levels of nesting, at most {MAX_DEPTH}")
    try:
        doc = json.loads(raw)
    except (ValueError, RecursionError) as exc:
        return WorldstateResult(raw, reason="malformed-json", detail=str(exc)[:80])
    if not isinstance(doc, dict):
        return WorldstateResult(raw, reason="malformed-json", detail="not a JSON object")
    if "type" not in doc:
        return WorldstateResult(raw, reason="missing-key", detail="type")
    if doc["type"] != "worldstate":
        return WorldstateResult(raw, reason="wrong-type", detail=f"type is {str(doc['type'])[:40]!r}")
    age = doc.get("ageMs")
    if type(age) not in (int, float) or not math.isfinite(age):
        return WorldstateResult(raw, reason="missing-key", detail="ageMs (a number)")
    for key in REQUIRED_STRINGS:
        if not isinstance(doc.get(key), str):
            return WorldstateResult(raw, reason="missing-key", detail=f"{key} (a string)")
    for key in REQUIRED_ARRAYS:
        if not isinstance(doc.get(key), list):
            return WorldstateResult(raw, reason="missing-key", detail=f"{key} (an array)")
    return WorldstateResult(raw, doc=doc)


class WorldstateReader:
    """Bytes from one base station in, one `WorldstateResult` per NUL-terminated message out.

    As the RefBox: a message longer than `MAX_UNTERMINATED` without its NUL is
    discarded with a `not-terminated` error. Unlike the RefBox, whose outcome
    depends on how TCP cut the stream, an overlong message is always that one
    error: the rest of it (up to its NUL) is discarded too instead of being
    parsed as a message of its own, and a message whose NUL arrives past the
    limit in the same read is `not-terminated` as well.
    """

    def __init__(self, limit: int = MAX_UNTERMINATED):
        self.limit = limit
        self._buf = bytearray()
        self._skipping = False

    def feed(self, data: bytes) -> list[WorldstateResult]:
        out: list[WorldstateResult] = []
        start = 0
        while True:
            end = data.find(b"\0", start)
            if end < 0:
                break
            if self._skipping:
                self._skipping = False
            else:
                self._buf += data[start:end]
                if len(self._buf) > self.limit:  # its NUL came, but too late (in the same read)
                    out.append(self._too_long())
                else:
                    out.append(validate_worldstate(self._buf.decode("utf-8", errors="replace")))
            self._buf.clear()
            start = end + 1
        if not self._skipping:
            self._buf += data[start:]
            if len(self._buf) > self.limit:
                out.append(self._too_long())
                self._buf.clear()
                self._skipping = True
        return out

    def _too_long(self) -> WorldstateResult:
        head = self._buf[:60].decode("utf-8", errors="replace")
        return WorldstateResult(head, reason="not-terminated", detail=f"no NUL within {self.limit} bytes")


# -------------------------------------------------------------- team table
def subnet_of(ip: str) -> str:
    """The RefBox's key for a client address: `a.b.c.*`; IPv6 loopback counts as 127.0.0.*."""
    try:
        addr = ipaddress.ip_address(ip.split("%", 1)[0])
    except ValueError:
        return ""
    if isinstance(addr, ipaddress.IPv6Address):
        if addr.ipv4_mapped is not None:
            addr = addr.ipv4_mapped
        elif addr.is_loopback:
            return "127.0.0.*"
        else:
            return ""
    a, b, c, _ = str(addr).split(".")
    return f"{a}.{b}.{c}.*"


def identify(ip: str, table: Iterable[TeamEntry]) -> TeamEntry | None:
    key = subnet_of(ip)
    return next((e for e in table if e.address == key), None) if key else None


def parse_team_table(text: str) -> tuple[TeamEntry, ...]:
    """A JSON array in msl_teams.json's form; `side` ("a"/"b") and `protocol` are optional."""
    try:
        rows = json.loads(text)
    except ValueError as exc:
        raise ProtocolError(f"team table is not JSON: {exc}") from None
    if not isinstance(rows, list):
        raise ProtocolError("team table must be a JSON array of objects")
    out = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict) or not isinstance(row.get("UnicastAddr"), str):
            raise ProtocolError(f"team table row {i}: needs a string UnicastAddr like '172.16.80.*'")
        addr = row["UnicastAddr"]
        parts = addr.split(".")
        if len(parts) != 4 or parts[3] != "*" or not all(p.isdigit() and int(p) < 256 for p in parts[:3]):
            raise ProtocolError(f"team table row {i}: UnicastAddr {addr!r} is not of the form a.b.c.*")
        side, protocol = row.get("side", ""), row.get("protocol", "json")
        if side not in ("a", "b", ""):
            raise ProtocolError(f"team table row {i}: side must be 'a' or 'b', got {side!r}")
        if protocol not in PROTOCOLS:
            raise ProtocolError(f"team table row {i}: protocol must be json or legacy, got {protocol!r}")
        out.append(TeamEntry(addr, str(row.get("Team", "")), str(row.get("MulticastAddr", "")), side, protocol))
    return tuple(out)


# ---------------------------------------------------------------- endpoints
def parse_endpoint(text: str, default_port: int = PORT) -> tuple[str, int]:
    """`tcp/HOST:PORT`, `HOST:PORT` or `tcp/[V6]:PORT` -> (host, port)."""
    body = text[4:] if text.startswith("tcp/") else text
    if "/" in body:
        raise ProtocolError(f"endpoint {text!r}: only tcp/HOST:PORT is supported")
    if body.startswith("["):
        host, _, rest = body[1:].partition("]")
        port_text = rest[1:] if rest.startswith(":") else ""
    else:
        host, _, port_text = body.rpartition(":") if ":" in body else (body, "", "")
    if not host:
        raise ProtocolError(f"endpoint {text!r}: no host (use e.g. tcp/0.0.0.0:{default_port})")
    try:
        port = int(port_text) if port_text else default_port
    except ValueError:
        raise ProtocolError(f"endpoint {text!r}: port {port_text!r} is not a number") from None
    if not 0 <= port < 65536:
        raise ProtocolError(f"endpoint {text!r}: port {port} out of range")
    return host, port
