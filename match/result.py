"""The result of one match, either engine: what `arena match --json` prints.

`assemble` builds a `MatchResult` out of the processes' `Summary`s (and what
the launcher saw of them, `Collected`); `MatchResult.to_dict()` is the JSON
object, whose keys README.md's table lists.
"""

from __future__ import annotations

import hashlib
from collections import Counter
from typing import Any

import msgspec
from msgspec import UNSET, UnsetType

from arena.config import MatchConfig, ProcessId
from arena.match.faults import Fault
from arena.match.faults import outcome as match_outcome
from arena.runtime.stats import percentile
from arena.schemas.messages import Referee, Summary

# The recorder and the viewer send no data, and the RefBox bridge's worldstates are
# what the teams sent (no process's input): the digest is the same with or without them.
NOT_COUNTED = frozenset(("recorder", "refbox", "viewer"))


def counted(cfg: MatchConfig) -> list[ProcessId]:
    """The processes whose digests make the match's, in the canonical order (the only place that says so)."""
    return [p for p in cfg.processes() if p.kind not in NOT_COUNTED]


def combined_digest(cfg: MatchConfig, digests: dict[str, str]) -> str:
    """The match digest of `arena match --json`: every counted process's digest, in order."""
    combined = hashlib.blake2b(digest_size=16)
    for p in counted(cfg):
        name = str(p)
        if name in digests:
            combined.update(name.encode() + b"=" + digests[name].encode() + b";")
    return combined.hexdigest()


class MatchError(RuntimeError):
    """The match could not be played to the end; the message says why."""


class JoinError(MatchError):
    """An `--external` process never joined (a user's or a network's matter: exit 2)."""


class Collected(msgspec.Struct):
    summaries: dict[str, Summary] = msgspec.field(default_factory=dict)
    pids: dict[str, int] = msgspec.field(default_factory=dict)
    forged: Counter = msgspec.field(default_factory=Counter)  # rejected summaries per key
    started: float = 0.0
    ended: float = 0.0
    crashed: dict[str, str] = msgspec.field(default_factory=dict)  # name -> why (exit code)
    lost: dict[str, str] = msgspec.field(default_factory=dict)  # liveliness gone before the summary
    missing: dict[str, str] = msgspec.field(default_factory=dict)  # no summary within the bound
    void: str = ""  # why the match is void, found while supervising
    lapsed: set[str] = msgspec.field(default_factory=set)  # tokens that vanished under load, frames kept coming
    last_referee: Referee | None = None  # the newest referee frame the launcher saw (a void match's ticks, score)


class ProcessRow(msgspec.Struct):
    """One process of the match: `processes` of `arena match --json`."""

    kind: str
    team: str | None
    robot: int | None
    pid: int | None
    external: bool
    tick_us_median: float | None  # its own work per tick [us]
    tick_us_p95: float | None
    cpu_s: float | None


class LinkStats(msgspec.Struct):
    """One link class of the match, over every process's links of it: `links` of `arena match --json`."""

    sent: int
    dropped: int
    drop_rate: float
    delay_ms_mean: float
    delay_ms_p95: float


class Parked(msgspec.Struct):
    """A dead robot taken off the field (processes/engine.py): `parked` of `arena match --json`."""

    tick: int
    x: float
    y: float


class SentOff(msgspec.Struct):
    """A robot sent off by a card or REPAIR_OUT (docs/rules.md): `sent_off` of `arena match --json`."""

    tick: int
    robot: str  # "b/1"
    command: str  # RED_CARD, DOUBLE_YELLOW, REPAIR_OUT


class MatchResult(msgspec.Struct, kw_only=True):
    """One match's result. Its fields, in order, are the keys of `arena match --json`
    (README.md, "What `arena match --json` reports"); those after `referee_log` are set by the
    engine that played it, and a field left UNSET is not printed. `recording`, `refbox`,
    `refbox_follow` and `referee_log` are what the recorder, the RefBox bridge and the referee
    report of themselves (their Summary's `extra`), as they report it."""

    outcome: str  # completed | void (match/faults.py)
    void: bool
    outcome_reasons: list[str]
    home: str
    away: str
    score: list[int]
    seed: int
    robots: int
    half_time: float
    link: str
    realtime: bool
    params: dict[str, dict[str, Any]]  # the strategy parameters each team was given (MatchConfig.params)
    engine: str  # processes | inprocess
    ticks: int
    sim_seconds: float
    wall_seconds: float
    play_wall_seconds: float
    rtf: float
    digest: str
    process_digests: dict[str, str]
    processes: list[ProcessRow]
    links: dict[str, LinkStats]
    events: dict[str, int]
    distance_m: dict[str, float]  # "a/1" -> metres driven
    parked: dict[str, Parked]  # "b/1" -> where and when
    sent_off: list[SentOff]
    rejected: int
    rejected_reasons: dict[str, int]
    dead: list[str]
    faults: list[Fault]
    conflicts: dict[str, int]
    forged: dict[str, int]
    liveliness_lapses: list[str]
    forged_summaries: dict[str, int]
    sent_by_key: dict[str, int]
    recording: dict[str, Any] | None
    refbox: dict[str, Any] | None
    refbox_follow: dict[str, Any] | None
    referee_log: list[dict[str, Any]]
    services: list[str] | UnsetType = UNSET  # arena up
    secure: bool | UnsetType = UNSET  # processes, arena up
    digests_verified: list[str] | UnsetType = UNSET  # processes
    refused_starts: list[dict] | UnsetType = UNSET  # processes: turned away at connect (match/claims.py)
    startup_seconds: float | None | UnsetType = UNSET  # processes, inprocess
    launch: str | UnsetType = UNSET  # processes: exec | fork | zygote; inprocess
    play_started_unix: float | None | UnsetType = UNSET  # processes, inprocess
    pid: int | UnsetType = UNSET  # inprocess
    deadlocks: list[str] | UnsetType = UNSET  # inprocess
    logs: str | UnsetType = UNSET  # processes: where a failed match's logs are kept
    # Never printed (`NOT_PRINTED`): what a caller in this process reads further.
    summaries: dict[str, Summary] = {}  # every process's own Summary, by name
    frames: dict[str, list[bytes]] = {}  # the payloads on each key `play(..., watch=...)` named, in order

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of `arena match --json` (typed parts as plain dicts; UNSET fields left out)."""
        return {
            f: msgspec.to_builtins(v)
            for f in self.__struct_fields__
            if f not in NOT_PRINTED and (v := getattr(self, f)) is not UNSET
        }


NOT_PRINTED = frozenset(("summaries", "frames"))


def assemble(
    cfg: MatchConfig, got: Collected, wall_total: float, pids: dict[str, int] | None = None, record: str = ""
) -> MatchResult:
    """The match result (what `arena match --json` prints)."""
    order = [str(p) for p in counted(cfg)]
    sums = got.summaries
    referee = sums.get("referee")
    engine = sums.get("engine")
    totals: dict[str, list] = {}  # class -> [sent, dropped, delays]
    for name in order:
        s = sums.get(name)
        if s is None:
            continue
        for cls, agg in s.links.items():
            acc = totals.setdefault(cls, [0, 0, []])
            acc[0] += int(agg["frames"])
            acc[1] += int(agg["dropped"])
            acc[2].extend(s.delays_ms.get(cls, []))
    links = {}
    for cls, (sent, dropped, delays) in totals.items():
        d = sorted(delays)
        links[cls] = LinkStats(
            sent=sent,
            dropped=dropped,
            drop_rate=round(dropped / sent, 5) if sent else 0.0,
            delay_ms_mean=round(sum(d) / len(d), 3) if d else 0.0,
            delay_ms_p95=round(percentile(d, 95), 3),
        )
    rejected = Counter()
    for s in sums.values():
        rejected.update(s.rejected_reasons)
    if got.forged:
        rejected["forged"] += sum(got.forged.values())
    pid_of = pids or {}
    processes = []
    for p in cfg.processes():
        name = str(p)
        s = sums.get(name)
        processes.append(
            ProcessRow(
                kind=p.kind,
                team=p.team or None,
                robot=p.robot if p.kind == "robot" else None,
                pid=s.pid if s is not None else pid_of.get(name),
                external=p.short in cfg.external or name in cfg.external,
                tick_us_median=round(s.tick_us[0], 1) if s and s.tick_us else None,
                tick_us_p95=round(s.tick_us[1], 1) if s and s.tick_us else None,
                cpu_s=round(sum(s.cpu_s), 3) if s and s.cpu_s else None,
            )
        )
    last = got.last_referee
    if referee is not None:
        score = list(referee.extra.get("score", [0, 0]))
    else:  # a void match without the referee's summary: the score of its last frame, as played
        score = [last.score_a, last.score_b] if last is not None else [0, 0]
    sent_by_key: dict[str, int] = {}
    for name in order:
        if name in sums:
            for key, n in sums[name].sent_by_key.items():
                sent_by_key[key] = sent_by_key.get(key, 0) + n
    recorder = sums.get("recorder")
    # Without the engine's summary (a void match): as far as the referee's frames went, as played.
    ticks = engine.tick if engine else max(referee.tick if referee else 0, last.tick if last is not None else 0)
    sim_seconds = ticks * cfg.timing.dt
    # Simulation speed is measured by the engine from its start barrier to its
    # last tick; process start-up is reported apart (wall_seconds).
    play = max(1e-9, engine.wall_s if engine and engine.wall_s > 0 else got.ended - got.started)
    honest = match_outcome(cfg, sums, got.crashed, got.lost, got.missing, got.void)
    recording = recorder.extra if recorder else None
    if cfg.tap and recorder is None:
        why = next((f.reason for f in honest.faults if f.process == "recorder"), "no summary")
        recording = {"path": record, "complete": False, "error": f"the recorder failed: {why}"}
    return MatchResult(
        outcome=honest.outcome,
        void=honest.void,
        outcome_reasons=honest.outcome_reasons,
        home=cfg.home,
        away=cfg.away,
        score=score,
        seed=cfg.seed,
        robots=cfg.robots,
        half_time=cfg.half_time,
        link=cfg.link,
        realtime=cfg.realtime,
        params=cfg.params,
        engine="processes",  # match/inprocess.py says "inprocess"
        ticks=ticks,
        sim_seconds=round(sim_seconds, 3),
        wall_seconds=round(wall_total, 3),
        play_wall_seconds=round(play, 3),
        rtf=round(sim_seconds / play, 2),
        digest=combined_digest(cfg, {name: s.digest for name, s in sums.items()}),
        process_digests={name: sums[name].digest for name in order if name in sums},
        processes=processes,
        links=links,
        events=dict(sorted(referee.extra.get("events", {}).items())) if referee else {},
        distance_m=engine.extra.get("distance_m", {}) if engine else {},
        parked={k: Parked(**v) for k, v in engine.extra.get("parked", {}).items()} if engine else {},
        sent_off=[SentOff(**s) for s in engine.extra.get("sent_off", [])] if engine else [],
        rejected=sum(rejected.values()),
        rejected_reasons=dict(rejected),
        dead=honest.dead,
        faults=honest.faults,
        conflicts=honest.conflicts,
        forged=honest.forged,
        liveliness_lapses=sorted(got.lapsed),
        forged_summaries=dict(sorted(got.forged.items())),
        sent_by_key=dict(sorted(sent_by_key.items())),
        recording=recording,
        refbox=sums["refbox"].extra if "refbox" in sums else None,
        refbox_follow=referee.extra.get("refbox_follow") if referee else None,
        referee_log=referee.extra.get("log", []) if referee else [],
        summaries=sums,
    )


def startup_seconds(summaries: dict[str, Summary], launched: float) -> float | None:
    """Launch (`play_match` called) to the engine's first tick, from the engine's Summary."""
    engine = summaries.get("engine")
    started = engine.extra.get("play_started", 0.0) if engine is not None else 0.0
    return round(started - launched, 3) if started else None
