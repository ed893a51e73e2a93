"""An honest match result: who failed, when, and whether the match counts.

The launcher observes three kinds of failure, each with the process's name:

* `crashed`: a child exited non-zero, or exited without a summary;
* `lost`: a process's liveliness token vanished before its summary came (a
  hang: SIGSTOP, a cut cable; or an external that left);
* `missing`: a process that never delivered its summary within the bound.

The processes themselves report whom they gave up waiting for (`Summary.dead`,
with their tick in `dead_at`). A process that was itself cut off sees everyone
else vanish, so its claims are not evidence: `blame` keeps only the claims the
launcher's own view of the liveliness tokens confirms. A peer that is alive but silent is claimed (`extra["silent"]`) only
by the receiver whose sender owes the frame: a receiver waits on while its
sender announces a wait of its own at a tick not past the missing frame, and
for a full wait_timeout after it took that announcement back
(runtime/drivers.py `Reactor`), so the processes downstream of a stalled
one make no claims of their own.

The outcome:

* `void`: the engine or the referee failed, or the match played fewer ticks
  than configured. It is no result: `arena match` exits 1, a tournament never
  counts it;
* `completed_with_faults`: played to the end, but a team process, the recorder
  or an external failed (a robot breaking down in a real match);
* `completed`: nothing failed.
"""

from __future__ import annotations

import signal
from typing import TYPE_CHECKING

import msgspec

from arena.config import MatchConfig
from arena.schemas.messages import Summary

if TYPE_CHECKING:
    from arena.match.result import MatchResult

# A failure of one of these makes the match void: without them there is no game.
VOIDING = ("engine", "referee")


class Fault(msgspec.Struct):
    """One failed process of a match: `faults` of `arena match --json`."""

    process: str  # e.g. "robot/b/1"
    tick: int | None  # when it was given up on (the engine's tick), None if nobody did
    reason: str  # "exited with code -9 (SIGKILL)", "stopped responding: ...", ...


class Verdict(msgspec.Struct, frozen=True):
    """What `outcome` finds: the match result's `outcome`, `void`, `outcome_reasons`, `dead`,
    `faults`, `conflicts` and `forged`."""

    outcome: str
    void: bool
    outcome_reasons: list[str]
    dead: list[str]
    faults: list[Fault]
    conflicts: dict[str, int]
    forged: dict[str, int]


def exit_reason(code: int) -> str:
    if code < 0:
        try:
            return f"exited with code {code} ({signal.Signals(-code).name})"
        except ValueError:
            pass
    return f"exited with code {code}"


def lapses(vanished: set[str], summaries: dict[str, Summary]) -> tuple[set[str], set[str]]:
    """(lost, lapsed): of the processes whose liveliness token vanished mid-match in the
    launcher's view and came back in time for their summary, which failed and which only lapsed.

    The launcher watches the tokens through its router, and a router under load (a flood of
    forged frames) loses leases of processes that never stopped. What tells them apart is the
    process's own frames: a peer that stopped (SIGSTOP, a cut cable) owed frames meanwhile, and
    whoever waited for them gave up on it (its `dead`). A process nobody gave up on kept its
    frames coming: a lapse under load, no failure. A process with no summary is not judged here.
    """
    claimed = {peer for s in summaries.values() for peer in s.dead}
    lapsed = {name for name in vanished if name in summaries and name not in claimed}
    return vanished - lapsed, lapsed


def blame(summaries: dict[str, Summary], lost: set[str]) -> dict[str, int]:
    """Who is dead: name -> tick.

    A claim "X is dead" (in a summary's `dead`) is credible when the launcher,
    a neutral observer, saw X's liveliness token vanish (`lost`), or X has no
    summary. A process that claims peers dead whom nobody else lost was itself
    cut off (stopped, unplugged): everyone vanished from its view at once. It
    is the one blamed, at its earliest such claim, and its claims are dropped.

    The tick is the engine's when it gave up on the process (the match clock),
    else the earliest claimant's.
    """
    dead: dict[str, int] = {}
    # A peer given up on as alive but silent (`extra["silent"]`): the claimant checked that the peer
    # was not itself waiting for its own upstream, nor had been for `wait_timeout`
    # (runtime/drivers.py `Reactor`), so the peer owes a frame. Taken in tick order: a process
    # already found silent is no witness against its peers (its base station muted its orders,
    # so it then found the base station silent in turn).
    silent = sorted(
        (int(tick), name, peer)
        for name, s in summaries.items()
        if name not in lost and isinstance(s.extra.get("silent"), dict)
        for peer, tick in s.extra["silent"].items()
        if isinstance(tick, int) and peer in s.dead
    )
    witnesses_gone: set[str] = set()
    for tick, name, peer in silent:
        if name in witnesses_gone:
            continue
        dead[peer] = min(tick, dead.get(peer, tick))
        witnesses_gone.add(peer)
    claimed = {(name, peer) for _, name, peer in silent}
    for name, s in summaries.items():
        for peer in s.dead:
            tick = s.dead_at.get(peer, s.tick)
            if (name, peer) in claimed or name in witnesses_gone:
                continue
            if name in lost and peer not in lost:
                continue  # a lost process's view of the others is no evidence
            if peer in lost or peer not in summaries:
                dead[peer] = min(tick, dead.get(peer, tick))
            else:
                dead[name] = min(tick, dead.get(name, tick))
    engine = summaries.get("engine")
    if engine is not None and "engine" not in dead:
        dead.update({p: t for p, t in engine.dead_at.items() if p in dead})  # the engine's tick is the match's
    return dead


def outcome(
    cfg: MatchConfig,
    summaries: dict[str, Summary],
    crashed: dict[str, str],
    lost: dict[str, str],
    missing: dict[str, str],
    void: str = "",
) -> Verdict:
    """Who failed, and whether the match counts (`Verdict`)."""
    dead = blame(summaries, set(lost))
    order = [str(p) for p in cfg.processes()]
    faults = []
    for name in order:
        why = crashed.get(name) or lost.get(name) or missing.get(name)
        if why is None and name in dead:
            claimed = any(name in s.dead for s in summaries.values())
            why = "stopped responding: its peers gave up waiting for it" if claimed else "lost contact with its peers"
        if why is None:
            continue
        faults.append(Fault(process=name, tick=dead.get(name), reason=why))
    reasons = []
    if void:
        reasons.append(void)
    for kind in VOIDING:
        f = next((f for f in faults if f.process == kind), None)
        if kind not in summaries and not void:
            reasons.append(f"{kind}: {f.reason}" if f else f"{kind}: no summary")
        elif f is not None and not (void and void.startswith(kind)):
            reasons.append(f"{kind}: {f.reason}")  # it failed, even if its summary came later
    referee = summaries.get("referee")
    follow = referee.extra.get("refbox_follow") if referee is not None else None
    if follow and not follow.get("connected"):
        # Our rules only end a followed match: without the RefBox nobody restarted play, so it decided nothing.
        reasons.append(f"--refbox-follow {follow['endpoint']}: never connected, so no referee at the RefBox ran it")
    engine = summaries.get("engine")
    ticks = engine.tick if engine is not None else 0
    if engine is not None and ticks < cfg.total_ticks:
        reasons.append(f"the engine played {ticks} of {cfg.total_ticks} ticks")
    if reasons:
        result = "void"
    elif faults:
        result = "completed_with_faults"
        reasons = [f"{f.process}: {f.reason}" for f in faults]
    else:
        result = "completed"
    conflicts: dict[str, int] = {}
    forged: dict[str, int] = {}
    for s in summaries.values():
        for key, n in s.conflicts.items():
            conflicts[key] = conflicts.get(key, 0) + n
        for key, n in s.forged.items():
            forged[key] = forged.get(key, 0) + n
    return Verdict(
        outcome=result,
        void=result == "void",
        outcome_reasons=reasons,
        dead=sorted(dead),
        faults=faults,
        conflicts=dict(sorted(conflicts.items())),
        forged=dict(sorted(forged.items())),
    )


def warnings(result: MatchResult) -> list[str]:
    """One line per fault and per key with forged or conflicting frames, for the terminal."""
    lines = []
    conflicts, forged = result.conflicts, result.forged
    for key in sorted({*conflicts, *forged}):
        # Forged ones are counted per message as it arrives (one message may batch several ticks'
        # frames), conflicting ones per frame the lockstep compared.
        counts = ((forged.get(key, 0), "forged message"), (conflicts.get(key, 0), "conflicting frame"))
        said = ", ".join(f"{n} {what}{'s' if n != 1 else ''}" for n, what in counts if n)
        lines.append(f"possible spoofing on {key} ({said})")
    for f in result.faults:
        at = f" at tick {f.tick}" if f.tick is not None else ""
        lines.append(f"fault: {f.process}{at}: {f.reason}")
    return lines
