"""Key expressions: every data pair is one zenoh key under `arena/<match>/`.

`KEYS` is the single table the wire contract (schemas/README.md), the
recorder and the process wiring are derived from."""

from __future__ import annotations

import re
from collections.abc import Mapping

import msgspec

from arena.schemas import messages as m
from arena.schemas.vocabulary import TEAMS

ROOT = "arena"
_MATCH_ID = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")


def check_match_id(match: str) -> str:
    if not _MATCH_ID.match(match):
        raise ValueError(f"bad match id {match!r}: use 1-64 characters of A-Z a-z 0-9 _ . -")
    return match


# The match's periods in ticks, by name. Each link's schedule names one of them;
# the values are the defaults of config.TimingParams (which reads them
# from here), and a match's own values come from its configuration.
DEFAULT_PERIODS: dict[str, int] = {"tick": 1, "comm": 5, "referee": 5, "world": 1}


class Timing(msgspec.Struct, frozen=True):
    """A link's schedule and lag, as data.

    The sender sends one frame at every tick phase, phase + P, phase + 2P, ...,
    where P is the match's period named `period` ("tick", "comm", "referee" or
    "world"; see `DEFAULT_PERIODS`) and `phase` is taken modulo P (so -1 is the
    last tick of each period). A frame sent at tick s is delivered at tick
    s + `lag` at the earliest. `period=None`: not a lockstep link (sent once, or
    whenever its sender likes); nobody waits for it.
    """

    period: str | None
    phase: int = 0
    lag: int = 1

    def schedule(self, periods: Mapping[str, int]) -> tuple[int, int]:
        """(period, phase) in ticks for a match whose periods are `periods`."""
        if self.period is None:
            raise ValueError("not a scheduled link")
        p = periods[self.period]
        return p, self.phase % p


class KeySpec(msgspec.Struct, frozen=True):
    name: str  # short name used in code and docs
    pattern: str  # relative to arena/<match>/, with <team> and <n> placeholders
    message: type[m.Base]
    data_pair: str  # the paper's name (Fig. 1 and 2)
    sender: str  # the sending process id, with <team> and <n> placeholders
    receivers: str
    timing: Timing
    link_class: str  # which link model applies on the receiving side
    note: str = ""  # what the schedule table adds about delivery

    def rel(self, team: str = "", n: int | None = None) -> str:
        key = self.pattern.replace("<team>", team)
        if n is not None:
            key = key.replace("<n>", str(n))
        return key

    def sender_id(self, team: str = "", n: int | None = None) -> str:
        """The process id of the sender of this key for (team, n)."""
        sid = self.sender.replace("<team>", team)
        return sid.replace("<n>", str(n)) if n is not None else sid


EVERY_TICK = Timing("tick", 0, lag=1)

KEYS: tuple[KeySpec, ...] = (
    KeySpec("field", "field", m.FieldSpec, "S_G / G_S", "engine", "all", Timing(None), "wired", "once, at tick 0"),
    KeySpec(
        "sense",
        "robot/<team>/<n>/sense",
        m.Sense,
        "G_R_n",
        "engine",
        "robot n",
        Timing("tick", 0, lag=0),
        "sensor",
        "the robot uses the sense of tick s from tick s + L, L = `timing.perception_latency`",
    ),
    KeySpec(
        "cmd",
        "robot/<team>/<n>/cmd",
        m.Cmd,
        "R_n_G",
        "robot/<team>/<n>",
        "engine",
        EVERY_TICK,
        "sensor",
        "the engine applies tick-k commands from k+1",
    ),
    KeySpec(
        "report",
        "team/<team>/report/<n>",
        m.Report,
        "R_n_B",
        "robot/<team>/<n>",
        "base station, viewers",
        Timing("comm", 0),
        "wifi",
    ),
    KeySpec(
        "order",
        "team/<team>/order/<n>",
        m.Order,
        "B_R_n",
        "basestation/<team>",
        "robot n, viewers",
        Timing("comm", 1),
        "wifi",
    ),
    KeySpec(
        "referee",
        "referee",
        m.Referee,
        "Re_G, Re_B",
        "referee",
        "engine, base stations, refbox, viewers",
        Timing("referee", 0),
        "wired",
    ),
    KeySpec(
        "events", "engine/events", m.EngineEvents, "G_Re", "engine", "referee, viewers", Timing("referee", -1), "wired"
    ),
    KeySpec(
        "world",
        "world",
        m.World,
        "G_V",
        "engine",
        "recorder, viewers",
        Timing("world", 0),
        "ideal",
        "for viewers; nobody waits for it",
    ),
    KeySpec(
        "worldstate",
        "refbox/<team>/worldstate",
        m.Worldstate,
        "B_RefBox",
        "refbox",
        "recorder",
        Timing(None),
        "ideal",
        "as the team's base station sends it (--refbox only)",
    ),
)

KEY_BY_NAME = {k.name: k for k in KEYS}

# [bytes] the longest frame a receiver reads on a data key; a longer one is counted as
# `too-large` and dropped unread. The largest legitimate frame (a `world` or `sense` with
# every robot of a full MSL match) is a few kB; 64 KiB is one zenoh batch, so no data
# frame ever needs zenoh's fragmentation, which relayed megabyte frames lose (schemas/contract.py).
MAX_FRAME_BYTES = 1 << 16

# Every frame on a data key of `KEYS`, every `summary/<p>` and every `tap/<p>` carries its sender's
# MAC in the zenoh attachment (runtime/mac.py), in every match, `--secure` or not.
# Keys (by name) whose sender also serves its last frame: the live viewer asks for what the
# teams believe a few times a second (processes/viewer.py) instead of subscribing, which
# would cost every robot and base station one more put per frame, many a second unpaced.
SERVED = ("report", "order")
MAX_BATCH = 64  # frames in one batch message at most (runtime/lockstep.py `Outbound.batch`)
MAC_BYTES = 16  # BLAKE2b digest size of a MAC
MAC_KEY_BYTES = 32  # a process's MAC key

# A read-only principal: world, referee, field, and what the teams believe (reports, orders)
# and the engine's ball events, which the live viewer draws (processes/viewer.py).
VIEWER = "viewer"


def process_names(robots: int, record: bool = True) -> list[str]:
    """Every process of a match with `robots` per team, in `MatchConfig.processes()` order."""
    names = ["engine", "referee"] + [f"basestation/{t}" for t in TEAMS]
    names += [f"robot/{t}/{n}" for t in TEAMS for n in range(robots)]
    return names + (["recorder"] if record else [])


def _who(role: str, team: str, n: int) -> list[str]:
    """The processes a `sender`/`receivers` word of the key table stands for."""
    role = role.strip().replace("<team>", team).replace("<n>", str(n))
    if role.startswith(("robot/", "basestation/")):
        return [role]
    if role == "robot n":
        return [f"robot/{team}/{n}"]
    if role == "base station":
        return [f"basestation/{team}"]
    if role == "base stations":
        return [f"basestation/{t}" for t in TEAMS]
    if role == "viewers":
        return [VIEWER]
    if role in ("engine", "referee", "recorder", "refbox"):
        return [role]
    raise ValueError(f"key table: unknown party {role!r}")


def routes(robots: int) -> list[tuple[str, str, tuple[str, ...]]]:
    """(key relative to arena/<m>/, sender, receivers) for every concrete data key of a match.

    Derived from the `sender` and `receivers` columns of `KEYS` alone; the
    access control of a secure match (runtime/acl.py) and the recorder's
    check of who may send what are built from it.
    """
    everyone = process_names(robots) + [VIEWER]
    out = []
    for spec in KEYS:
        teams = TEAMS if "<team>" in spec.pattern else ("",)
        numbers = range(robots) if "<n>" in spec.pattern else (0,)
        for team in teams:
            for n in numbers:
                rel = spec.rel(team, n if "<n>" in spec.pattern else None)
                (sender,) = _who(spec.sender, team, n)
                if spec.receivers == "all":
                    receivers = [p for p in everyone if p != sender]
                else:
                    receivers = [p for word in spec.receivers.split(",") for p in _who(word, team, n)]
                out.append((rel, sender, tuple(receivers)))
    return out


# Infrastructure keys (not data pairs of the paper).
ALIVE = "alive"  # liveliness tokens: arena/<m>/alive/<process id>
# arena/<m>/waiting/<process id>/<tick>: liveliness token of a process blocked for a while before acting at <tick>
WAITING = "waiting"
SUMMARY = "summary"  # arena/<m>/summary/<process id>: one Summary per process at the end
CONFIG = "config"  # queryable: the match configuration as JSON
ACK = "ack"  # arena/<m>/ack/<process id>: a collector acknowledges a summary
COLLECTOR = "collector"  # liveliness token of a summary collector (arena match, arena up)
REFUSED = "refused"  # arena/<m>/refused/<process id>: a second process with that identity was turned away
# arena/<m>/claim/<process id>: queryable of the match's router, which gives each identity to one process;
# arena/<m>/claim/<process id>/<nonce>: the claimant's liveliness token, held while it runs
CLAIM = "claim"
# arena/<m>/spoofing/<process id, / as ->/<key>: liveliness token of a process that dropped a forged
# frame, or counted a conflicting one, on <key> (relative to arena/<m>/); the launcher prints each key once
SPOOFING = "spoofing"
TAP = "tap"  # arena/<m>/tap/<process id>: TapBatch, only when the match records
CONTROL = "control"  # arena/<m>/control: Control frames, viewer -> engine, live lockstep matches only
OPERATOR = "operator"  # arena/<m>/operator: Operator frames -> engine and referee, live sessions only
OPERATOR_PRINCIPAL = "operator"  # the one principal the access control lets put them
TAP_PERIOD = 50  # [ticks] one tap batch per process every 1 s of simulated time (at 20 ms ticks)


class Keys:
    """Absolute key builders for one match."""

    def __init__(self, match: str):
        self.match = check_match_id(match)
        self.prefix = f"{ROOT}/{match}/"

    def key(self, name: str, team: str = "", n: int | None = None) -> str:
        return self.prefix + KEY_BY_NAME[name].rel(team, n)

    def rel(self, key: str) -> str:
        """Key without the match prefix (digests must not depend on the match id)."""
        return key[len(self.prefix) :] if key.startswith(self.prefix) else key

    def alive(self, process: str) -> str:
        return f"{self.prefix}{ALIVE}/{process}"

    def alive_all(self) -> str:
        return f"{self.prefix}{ALIVE}/**"

    def waiting(self, process: str, tick: int) -> str:
        return f"{self.prefix}{WAITING}/{process}/{tick}"

    def waiting_all(self) -> str:
        return f"{self.prefix}{WAITING}/**"

    def spoofing(self, process: str, rel: str) -> str:
        """`robot/a/1` saw spoofing on `referee`: arena/<m>/spoofing/robot-a-1/referee."""
        return f"{self.prefix}{SPOOFING}/{process.replace('/', '-')}/{rel}"

    def spoofing_all(self) -> str:
        return f"{self.prefix}{SPOOFING}/**"

    def summary(self, process: str) -> str:
        return f"{self.prefix}{SUMMARY}/{process}"

    def summary_all(self) -> str:
        return f"{self.prefix}{SUMMARY}/**"

    def tap(self, process: str) -> str:
        return f"{self.prefix}{TAP}/{process}"

    def tap_all(self) -> str:
        return f"{self.prefix}{TAP}/**"

    def control(self) -> str:
        return f"{self.prefix}{CONTROL}"

    def operator(self) -> str:
        return f"{self.prefix}{OPERATOR}"

    def ack(self, process: str) -> str:
        return f"{self.prefix}{ACK}/{process}"

    def refused(self, process: str) -> str:
        return f"{self.prefix}{REFUSED}/{process}"

    def refused_all(self) -> str:
        return f"{self.prefix}{REFUSED}/**"

    def claim(self, process: str) -> str:
        return f"{self.prefix}{CLAIM}/{process}"

    def claim_token(self, process: str, nonce: str) -> str:
        return f"{self.prefix}{CLAIM}/{process}/{nonce}"

    def claim_all(self) -> str:
        return f"{self.prefix}{CLAIM}/**"

    def collector(self) -> str:
        return f"{self.prefix}{COLLECTOR}"

    def config(self) -> str:
        return f"{self.prefix}{CONFIG}"

    def everything(self) -> str:
        return f"{self.prefix}**"


def spec_of(rel: str) -> KeySpec | None:
    """The KeySpec of a concrete key relative to arena/<match>/ (`robot/a/1/cmd`), or None."""
    for spec in KEYS:
        pattern = re.escape(spec.pattern).replace(re.escape("<team>"), "[ab]").replace(re.escape("<n>"), "[0-9]+")
        if re.fullmatch(pattern, rel):
            return spec
    return None
