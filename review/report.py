"""Human-readable output (rich tables) for match results."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.console import Console
from rich.table import Table

from arena.review.console import console as make_console

if TYPE_CHECKING:
    from arena.match import MatchResult


def print_match(result: MatchResult, console: Console | None = None) -> None:
    console = console or make_console()
    a, b = result.score
    console.print(
        f"[bold]{result.home}[/] (a) [bold]{a} : {b}[/] [bold]{result.away}[/] (b)   "
        f"seed {result.seed}, link {result.link}, engine {result.engine}"
    )
    console.print(
        f"{result.sim_seconds:.1f} s simulated in {result.play_wall_seconds:.2f} s "
        f"(rtf {result.rtf:.1f}x); {result.wall_seconds:.2f} s with start-up; digest {result.digest[:16]}"
    )
    goals = [e for e in result.referee_log if e["command"] == "GOAL"]
    if goals:
        dt = result.sim_seconds / max(1, result.ticks)
        console.print("goals: " + ", ".join(f"{e['team']} {e['tick'] * dt:.1f}s" for e in goals))
    t = Table(title="links", show_header=True)
    for col in ("class", "sent", "dropped", r"dropped \[%]", r"delay mean \[ms]", r"delay p95 \[ms]"):
        t.add_column(col, justify="right")
    for cls, s in sorted(result.links.items()):
        t.add_row(
            cls,
            str(s.sent),
            str(s.dropped),
            f"{100 * s.drop_rate:.2f}",
            f"{s.delay_ms_mean:.2f}",
            f"{s.delay_ms_p95:.2f}",
        )
    console.print(t)
    d = Table(title=r"distance per robot \[m]")
    d.add_column("robot")
    d.add_column(r"\[m]", justify="right")
    for name, m in result.distance_m.items():
        d.add_row(name, f"{m:.1f}")
    console.print(d)
    events = ", ".join(f"{k} {v}" for k, v in result.events.items())
    console.print(f"referee: {events}")
    if result.rejected:
        console.print(f"[yellow]rejected inputs: {result.rejected} {result.rejected_reasons}[/]")
    if result.dead:
        console.print(f"[red]treated as dead: {', '.join(result.dead)}[/]")
    rb = result.refbox
    if rb:
        c = rb["counts"]
        errors = {t: sum(e.values()) for t, e in rb["worldstate_errors"].items()}
        console.print(
            f"refbox (tcp port {rb['port']}): {c.get('connections', 0)} base station(s), {c.get('refused', 0)} refused, "
            f"{rb['commands_forwarded']} commands forwarded; worldstates a {c.get('worldstates_a', 0)} "
            f"({errors.get('a', 0)} bad), b {c.get('worldstates_b', 0)} ({errors.get('b', 0)} bad)"
        )
    fo = result.refbox_follow
    if fo:  # a human referee's RefBox: say whether it was ever there, or the match was a silent 0:0
        ignored = sum(fo["ignored"].values())
        state = "connected" if fo["connected"] else "[red]never connected[/]"
        console.print(
            f"refbox-follow {fo['endpoint']}: {state}; {fo['applied']} commands applied, "
            f"{ignored} ignored, {fo['errors']} malformed"
        )
    rec = result.recording
    if rec and "error" in rec:  # no recorder Summary (match/result.py)
        console.print(f"[red]not recorded[/]: {rec['error']} ({rec['path']})")
    elif rec:
        state = "complete" if rec["complete"] else f"[yellow]incomplete, missing {', '.join(rec['missing'])}[/]"
        console.print(
            f"recorded {sum(rec['messages'].values())} messages to {rec['path']} ({state}): arena review {rec['path']}"
        )
