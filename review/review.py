"""`arena review FILE.mcap`: what happened in a recorded match.

The analysis is `arena.recording.analysis` (shared with `arena facts` and the
tests); this module prints it and draws the plots.

Everything comes from the recording itself (recording/reader.py): the match
configuration from its `arena` metadata, score, goals and restarts from the
`referee` frames, possession, distances and trajectories from the `world`
frames, link statistics and timing from the processes' Summaries.

A truncated recording (the recorder was killed) is reviewed up to where it
ends, and the report says so. `--plots DIR` adds PNG charts and an animated
GIF (review/plots.py and review/animation.py).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from rich.console import Console
from rich.table import Table

from arena.recording.analysis import NEEDED, analyse
from arena.recording.reader import Recording, RecordingError, load
from arena.review import animation
from arena.review import plots as pictures
from arena.review.console import console as make_console
from arena.schemas.messages import Referee, World

TEAM_COLOURS = {"a": "#00bfff", "b": "#ff1abf"}  # MSL cyan and magenta, as in the Foxglove scene


# ------------------------------------------------------------------ output
def print_review(r: dict, console: Console | None = None) -> None:  # noqa: C901, PLR0912 - one section of the report per branch
    console = console or make_console()
    a, b = r["score"]
    console.print(
        f"[bold]{r['home']}[/] (a) [bold]{a} : {b}[/] [bold]{r['away']}[/] (b)   seed {r['seed']}, link {r['link']}"
    )
    console.print(
        f"{r['sim_seconds']:.1f} s of {r['planned_sim_seconds']:.1f} s recorded; git {r['git_revision'][:12]}"
    )
    if r["truncated"]:
        console.print(f"[yellow]truncated recording: {r['truncation']}; reviewed up to {r['sim_seconds']:.1f} s[/]")
    elif r.get("interrupted"):
        # Ctrl-C or a SIGTERM stopped the recorder (with the match, or alone): what came after is not a gap.
        how = {"SIGINT": "SIGINT (Ctrl-C)"}.get(r["interrupted"], r["interrupted"])
        console.print(
            f"[yellow]stopped recording: the recorder was stopped by {how} after {r['sim_seconds']:.1f} s of "
            f"{r['planned_sim_seconds']:.1f} s; reviewed up to there[/]"
        )
    elif not r["complete"]:
        console.print("[yellow]incomplete recording: the recorder missed some process's frames (gaps below)[/]")
    if r.get("undecodable"):
        bad = ", ".join(f"{topic} {n}" for topic, n in r["undecodable"].items())
        console.print(f"[yellow]skipped messages that do not decode as their topic's type: {bad}[/]")
    if r["goals"]:
        console.print(
            "goals: " + ", ".join(f"{g['t']:.1f} s {g['team']} ({g['score'][0]}:{g['score'][1]})" for g in r["goals"])
        )
    else:
        console.print("goals: none")
    for name, gap in ({} if r.get("interrupted") else r.get("gaps", {})).items():
        lost = ", ".join(f"{a}-{b}" for a, b in gap.get("lost_batches", []))
        keys = ", ".join(f"{k} {c['recorded']} of {c['sent']}" for k, c in gap.get("keys", {}).items())
        what = "; ".join(x for x in (lost and f"tap batches {lost} lost", keys, gap.get("summary", "")) if x)
        console.print(f"[yellow]gap: {name}: {what}[/]")
    for f in r.get("faults", []):
        console.print(f"[red]fault: {f['process']} at {f['t']:.1f} s (tick {f['tick']}): {f['reason']}[/]")
    console.print("restarts: " + (", ".join(f"{k} {v}" for k, v in r["restarts"].items()) or "none"))
    p = r["possession_percent"]
    console.print(
        f"possession: a {p['a']:.1f} %, b {p['b']:.1f} % (ball loose {p['loose_percent_of_time']:.1f} % of the time)"
    )
    f = r.get("facts")
    if f is not None:
        a, b = f["teams"]
        console.print(
            f"shots a {a['shots']} ({a['on_target']} on target), b {b['shots']} ({b['on_target']}); "
            f"keeper saves a {a['saves']}, b {b['saves']}; blocks a {a['blocks']}, b {b['blocks']}; "
            f"robot contact {f['contact_s']:.1f} pair-s"
        )
    d = Table(title="distance per robot", caption=f"from the {r['distance_source']}", min_width=30)
    d.add_column("robot")
    d.add_column(r"\[m]", justify="right")
    for name, m in r["distance_m"].items():
        d.add_row(name, f"{m:.1f}")
    console.print(d)
    links = r["links"]["by_class"]
    if links:
        t = Table(title="links (applied by the receivers)")
        for col in ("class", "frames", "dropped", r"dropped \[%]", r"delay p50 \[ms]", r"p95 \[ms]", r"p99 \[ms]"):
            t.add_column(col, justify="right")
        for cls, s in links.items():
            dm = s["delay_ms"]
            t.add_row(
                cls,
                str(s["frames"]),
                str(s["dropped"]),
                f"{s['drop_percent']:.2f}",
                f"{dm['p50']:.2f}",
                f"{dm['p95']:.2f}",
                f"{dm['p99']:.2f}",
            )
        console.print(t)
    else:
        console.print("[yellow]links: no process summaries in the file[/]")
    if r["timing"]:
        t = Table(title="per-process tick timing (own work)")
        for col in ("process", r"median \[us]", r"p95 \[us]", r"wall \[s]", r"CPU \[s]"):
            t.add_column(col, justify="right")
        for name, s in r["timing"].items():
            t.add_row(
                name,
                f"{s['tick_us_median']:.0f}" if s["tick_us_median"] is not None else "-",
                f"{s['tick_us_p95']:.0f}" if s["tick_us_p95"] is not None else "-",
                f"{s['wall_s']:.2f}",
                f"{s['cpu_s']:.2f}" if s["cpu_s"] is not None else "-",
            )
        console.print(t)
    if r.get("worldstate_accuracy"):
        print_worldstate_accuracy(r["worldstate_accuracy"], console)


def print_worldstate_accuracy(acc: dict, console: Console) -> None:
    """One table per team that sent worldstates through the RefBox bridge (recording/analysis/worldstates.py)."""
    for team, s in acc.items():
        t = Table(
            title=f"worldstate accuracy, team {team} ({s['worldstates']} worldstates)",
            caption="against the ground truth at the tick each describes (docs/refbox.md)",
        )
        for col in ("what", "n", "mean", "p95", "max"):
            t.add_column(col, justify="right")

        def row(name: str, st: dict, unit: str, t: Table = t) -> None:
            t.add_row(name, str(st["n"]), *(f"{st[k]:.3f} {unit}" for k in ("mean", "p95", "max")))

        for n, r in s["robots"].items():
            row(f"robot {n} position", r["position_m"], "m")
            row(f"robot {n} heading", r["heading_rad"], "rad")
        row("ball position", s["ball_m"], "m")
        row("ageMs", s["age_ms"], "ms")
        o = s["obstacles"]
        pct = {k: "-" if o[k] is None else f"{100 * o[k]:.1f} %" for k in ("recall", "precision")}
        t.add_row(f"obstacles within {o['radius_m']} m", str(o["reported"]), f"recall {pct['recall']}", "", "")
        t.add_row("", "", f"precision {pct['precision']}", "", "")
        console.print(t)
        if s["ball_missing"] or s["unmatched_robots"]:
            console.print(
                f"team {team}: no ball in {s['ball_missing']} worldstates; "
                f"{s['unmatched_robots']} robot entries with an unknown id or no pose"
            )


# ------------------------------------------------------------------- plots
def _draw_field(ax, cfg, grass: bool = True) -> None:
    from matplotlib.patches import Arc, Circle, Rectangle

    f = cfg.field
    hl, hw = f.length / 2, f.width / 2
    if grass:
        ax.set_facecolor("#2e7d32")
    ax.add_patch(Rectangle((-hl, -hw), f.length, f.width, fill=False, ec="white", lw=1.5))
    ax.plot([0, 0], [-hw, hw], color="white", lw=1)
    ax.add_patch(Circle((0, 0), f.center_circle_radius, fill=False, ec="white", lw=1))
    for side in (-1, 1):
        gx = side * hl
        for depth, width in ((f.penalty_area_depth, f.penalty_area_width), (f.goal_area_depth, f.goal_area_width)):
            x0 = gx if side < 0 else gx - depth
            ax.add_patch(Rectangle((x0, -width / 2), depth, width, fill=False, ec="white", lw=1))
        x0 = gx if side > 0 else gx - f.goal_depth
        ax.add_patch(Rectangle((x0, -f.goal_width / 2), f.goal_depth, f.goal_width, fc="white", alpha=0.5, ec="white"))
        for cy in (-hw, hw):
            # the quarter of the corner circle that lies inside the field
            start = {(1, -1): 90, (1, 1): 180, (-1, 1): 270, (-1, -1): 0}[(side, 1 if cy > 0 else -1)]
            ax.add_patch(
                Arc(
                    (gx, cy),
                    2 * f.corner_arc_radius,
                    2 * f.corner_arc_radius,
                    theta1=start,
                    theta2=start + 90,
                    color="white",
                    lw=1,
                )
            )
    ax.set_xlim(-hl - f.runoff, hl + f.runoff)
    ax.set_ylim(-hw - f.runoff, hw + f.runoff)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def write_plots(rec: Recording, review: dict, out_dir: str, goalkeepers: bool = False) -> list[str]:
    """PNG charts and an animated GIF of the match; returns the paths written.

    Trajectories and heatmaps are review/plots.py's; `goalkeepers` puts them in the heatmaps.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = rec.cfg
    worlds: list[World] = rec.decoded("world", World)
    written = []
    if worlds:
        written.append(pictures.trajectories(worlds, cfg, out / "trajectories.png", _draw_field))
        written.append(pictures.heatmap(worlds, cfg, out / "heatmap.png", _draw_field, goalkeepers))

    fig, ax = plt.subplots(figsize=(9, 4))
    end = review["sim_seconds"]
    for i, team in enumerate("ab"):
        times = [0.0] + [g["t"] for g in review["goals"]] + [end]
        scores = [0] + [g["score"][i] for g in review["goals"]] + [review["score"][i]]
        ax.step(
            times,
            scores,
            where="post",
            color=TEAM_COLOURS[team],
            ls="-" if team == "a" else "--",
            lw=2,
            label=f"{team}: {review['home' if team == 'a' else 'away']}",
        )
    ax.axvline(cfg.half_time, color="grey", ls=":", lw=0.8)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylim(-0.1, max(1, *review["score"]) + 0.5)
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel("goals")
    ax.set_title("score")
    ax.legend()
    written.append(_save(fig, out / "score.png"))

    if worlds:
        refs = rec.decoded("referee", Referee)
        written.append(animation.animate(worlds, cfg, out / "match.gif", refs, _draw_field))
    return written


def _save(fig, path: Path) -> str:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return str(path)


def main(
    path: str, plots: str | None = None, as_json: bool = False, goalkeepers: bool = False, html: str | None = None
) -> int:
    try:
        rec = load(path, keep=NEEDED)
        review = analyse(rec)
        if plots:
            review["plots"] = write_plots(rec, review, plots, goalkeepers)
        if html:
            from arena.review.replay_page import write_page

            try:
                review["html"] = write_page(rec, html)
            except OSError as exc:
                print(f"arena review: error: cannot write --html {html}: {exc.strerror}", file=sys.stderr)
                return 2
    except RecordingError as exc:  # the file, or a frame in it no match sends: in every mode
        print(f"arena review: error: {exc}", file=sys.stderr)
        return 2
    if as_json:
        print(json.dumps(review, indent=2))
    else:
        print_review(review)
        for p in review.get("plots", []):
            print(f"wrote {p}")
        if "html" in review:
            print(f"wrote {review['html']['path']} ({review['html']['bytes'] / 1e6:.2f} MB, open it in any browser)")
    return 0
