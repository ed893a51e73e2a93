"""A tournament's outputs in `--out` (Markdown, CSV, JSON, PNG) and its summary on
the terminal: Table 1 and 2, coverage, the goal-difference chart, ratings."""

from __future__ import annotations

import csv
import io
import json
from dataclasses import asdict
from itertools import combinations
from pathlib import Path

from arena.experiments.fixtures import Result, plural, short, write_atomic
from arena.experiments.ratings import coverage, ratings, standings


def show_value(value) -> str:
    """A setting's value as `arena tournament` prints it."""
    if isinstance(value, list):
        return ",".join(short(v) for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, dict):
        return ",".join(f"{c}.{p}={v:g}" for c, ps in sorted(value.items()) for p, v in sorted(ps.items())) or "none"
    return str(value)


def table1_rows(results: list[Result], strategies: list[str], legs: int) -> tuple[list[str], list[list[str]]]:
    pairs = list(combinations(strategies, 2))
    header = ["leg"] + [f"{short(a)} vs {short(b)}" for a, b in pairs]
    by_key = {(r.first, r.second, r.leg): r for r in results}
    rows = []
    for leg in range(1, legs + 1):
        row = [str(leg)]
        for a, b in pairs:
            r = by_key.get((a, b, leg))
            if r is None:
                row.append("")
            elif r.status != "ok":
                row.append("failed")
            else:
                row.append(f"{r.goals(a)[0]}-{r.goals(b)[0]}")
        rows.append(row)
    return header, rows


def markdown(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def csv_text(header: list[str], rows: list[list]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue()


def charts(out: Path, table: list[dict], cover: dict[str, dict]) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    written = []
    teams = [r["team"] for r in table]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    gd = [r["GD"] for r in table]
    bars = ax.bar([short(t) for t in teams], gd, color=["tab:green" if g >= 0 else "tab:red" for g in gd])
    ax.bar_label(bars, labels=[f"{g:+d}" if g else "0" for g in gd], padding=2)  # a 0 is said, not left blank
    ax.axhline(0, color="black", linewidth=0.8)
    top = max(1, *(abs(g) for g in gd)) * 1.25  # whole goals: never a +-0.04 axis when every GD is 0
    ax.set_ylim(-top, top)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("goal difference")
    ax.set_title("Goal difference per strategy (paper Fig. 8)" + ("" if any(gd) else ": all level"))
    fig.tight_layout()
    fig.savefig(out / "goal_difference.png", dpi=120)
    plt.close(fig)
    written.append(out / "goal_difference.png")

    fig, ax = plt.subplots(figsize=(6, 3.5))
    xs = range(len(teams))
    ax.bar([x - 0.2 for x in xs], [cover[t]["robot1_m"] for t in teams], width=0.4, label="robot 1")
    ax.bar([x + 0.2 for x in xs], [cover[t]["robot2_m"] for t in teams], width=0.4, label="robot 2")
    for x, t in zip(xs, teams):
        ratio = cover[t]["ratio"]
        if ratio is not None:
            ax.annotate(f"{ratio:.2f}", (x, max(cover[t]["robot1_m"], cover[t]["robot2_m"])), ha="center", va="bottom")
    ax.set_xticks(list(xs), [short(t) for t in teams])
    ax.set_ylabel("mean distance per match [m]")
    ax.margins(y=0.15)
    ax.set_title("Coverage of robot 1 and robot 2, with ratio (paper Fig. 9)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, frameon=False)  # below: never over a label
    fig.tight_layout()
    fig.savefig(out / "coverage.png", dpi=120)
    plt.close(fig)
    written.append(out / "coverage.png")
    return written


def report(
    results: list[Result],
    strategies: list[str],
    legs: int,
    out: Path,
    wall: float,
    seed: int,
    engine: str = "processes",
    total: int | None = None,
    setup: dict | None = None,
) -> dict:
    """Write every table and chart to `out`; return the JSON summary. `engine`: which one played.

    `total`: the matches the schedule has (more than `results` when interrupted);
    `setup`: the tournament's settings (`settings()`), recorded in both outputs.
    """
    total = len(results) if total is None else total
    setup = setup or {"strategies": strategies, "legs": legs, "seed": seed, "engine": engine}
    done = [r for r in results if r.status == "ok"]
    table = standings(results, strategies)
    cover = coverage(results, strategies)
    rates, notes = ratings(results, strategies, seed=seed)
    failed = [{"id": r.id, "reason": r.reason} for r in results if r.status != "ok"]
    faulty = [{"id": r.id, **f} for r in results if r.status == "ok" for f in r.faults]

    h1, rows1 = table1_rows(results, strategies, legs)
    cols2 = ["team", "W", "D", "L", "GF", "GA", "GD", "P"]
    rows2 = [[short(r["team"])] + [r[c] for c in cols2[1:]] for r in table]
    cols3 = ["team", "robot1_m", "robot2_m", "ratio"]
    rows3 = [[short(t)] + [cover[t][c] for c in cols3[1:]] for t in strategies]
    rows4 = [[short(r["team"]), *(["", "", ""] if r["rating"] is None else [r["rating"], *r["ci95"]])] for r in rates]
    cols4 = ["team", "rating", "ci95_low", "ci95_high"]
    for name, head, rows in (
        ("table1", h1, rows1),
        ("table2", cols2, rows2),
        ("coverage", cols3, rows3),
        ("ratings", cols4, rows4),
    ):
        write_atomic(out / f"{name}.csv", csv_text(head, rows))
    md = [
        f"# Tournament: {', '.join(short(s) for s in strategies)}, {plural(legs, 'leg')}, seed {seed}",
        "",
        f"{len(done)} of {plural(total, 'match', 'matches')} played ({len(failed)} failed), "
        f"{wall:.0f} s of wall time, engine {engine} (arena tournament --engine).",
        "",
        "Settings: " + ", ".join(f"{k.replace('_', ' ')} {show_value(v)}" for k, v in setup.items()) + ".",
        "",
        "## Table 1: scores per pairing and leg (first-named team's goals first)",
        "",
        markdown(h1, rows1),
        "## Table 2: standings (3 points a win, 1 a draw; ranked by P, GD, GF)",
        "",
        markdown(cols2, rows2),
        "## Coverage: mean distance per match of robot 1 and robot 2 (paper Fig. 9)",
        "",
        markdown(cols3, rows3),
        "## Ratings: Bradley-Terry, 95 % bootstrap intervals",
        "",
        markdown(cols4, rows4),
    ]
    if notes:
        md += ["Notes:", ""] + [f"- {n}" for n in notes] + [""]
    if failed:
        md += ["## Failed matches", ""] + [f"- {f['id']}: {f['reason']}" for f in failed] + [""]
    if faulty:
        md += ["## Matches played with faults (they count: a team's crash is the team's own)", ""]
        md += [f"- {f['id']}: {f['process']} at tick {f['tick']}: {f['reason']}" for f in faulty] + [""]
    if done:
        charts(out, table, cover)
        md += ["![goal difference](goal_difference.png)", "", "![coverage](coverage.png)", ""]
    write_atomic(out / "report.md", "\n".join(md))
    summary = {
        "strategies": strategies,
        "legs": legs,
        "seed": seed,
        "settings": setup,
        "played": len(done),
        "scheduled": total,
        "table": table,
        "coverage_ratio": {t: cover[t]["ratio"] for t in strategies},
        "coverage": cover,
        "ratings": rates,
        "notes": notes,
        "matches": [asdict(r) for r in results],
        "failed": failed,
        "faults": faulty,
        "wall_seconds": round(wall, 2),
        "engine": engine,
        "out": str(out),
    }
    write_atomic(out / "tournament.json", json.dumps(summary, indent=2))
    return summary


def print_summary(summary: dict) -> None:
    from rich.table import Table

    from arena.review.console import console as make_console

    c = make_console()
    t = Table(title="standings (3/1/0; by P, GD, GF)")
    for col in ("team", "W", "D", "L", "GF", "GA", "GD", "P", "rating (95 % CI)", "robot1/robot2"):
        t.add_column(col, justify="right")
    rate = {r["team"]: r for r in summary["ratings"]}
    for row in summary["table"]:
        team = row["team"]
        rr = rate[team]
        ratio = summary["coverage_ratio"][team]
        t.add_row(
            short(team),
            *(str(row[k]) for k in ("W", "D", "L", "GF", "GA", "GD", "P")),
            "-" if rr["rating"] is None else f"{rr['rating']:.0f} ({rr['ci95'][0]:.0f}..{rr['ci95'][1]:.0f})",
            "-" if ratio is None else f"{ratio:.2f}",
        )
    c.print(t)
    for note in summary["notes"]:
        c.print(f"[yellow]note:[/] {note}")
    for f in summary["failed"]:
        c.print(f"[red]failed:[/] {f['id']}: {f['reason']}")
    if "played" in summary:
        c.print(f"{summary['played']} of {plural(summary['scheduled'], 'match', 'matches')} played")
    c.print(
        f"tables, charts and per-match results in {summary['out']} "
        f"({summary['wall_seconds']:.0f} s, engine {summary.get('engine', 'processes')})"
    )
