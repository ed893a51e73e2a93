"""The bench's results as rich tables on the terminal, next to the papers' numbers."""

from __future__ import annotations

from typing import Any

from arena.experiments.navbench.report import Report, method_rows, minima_rows, results_rows, timing
from arena.experiments.navbench.spec import (
    FSFM_BUDGET_US,
    METHODS,
    PAPER_FIS_OVERHEAD,
    PAPER_FSFM_MS,
    PAPER_SFM_MS,
)


def print_report(r: Report, console: Any = None) -> None:
    from rich.markup import escape
    from rich.table import Table

    if console is None:
        from arena.review.console import console as make_console

        console = make_console()
    rows = results_rows(r)
    methods = method_rows(r)
    for sc in r.spec.scenarios:
        ref = f", paper 1 {sc.spec.paper}" if sc.spec.paper else ""
        t = Table(title=f"{sc.name}: {sc.spec.title or ''} ({r.trials} trials{ref})", title_justify="left")
        for col, just in [
            ("scheme", "left"),
            ("method", "left"),
            ("avg iter", "right"),
            ("paper", "right"),
            ("reached", "right"),
            ("collision-free", "right"),
            ("paper", "right"),
            ("safe %", "right"),
            ("paper %", "right"),
            (r"step \[us]", "right"),
        ]:
            t.add_column(col, justify=just)
        for row in (x for x in rows if x["scenario"] == sc.name):
            pf = row["paper_collision_free"]
            t.add_row(
                row["scheme"],
                row["label"],
                _fmt(row["avg_iterations"], "{:.1f}"),
                _fmt(row["paper_avg_iterations"], "{:g}"),
                f"{row['reached']}/{row['trials']}",
                f"{row['collision_free']}/{row['trials']}",
                "-" if pf is None else f"{pf}/10",
                f"{100 * row['safe_rate']:.0f}",
                _fmt(row["paper_safe_rate"], "{:.0%}").rstrip("%"),
                _fmt(row["us_per_iteration"], "{:.1f}"),
            )
        t.add_section()
        for mrow in (x for x in methods if x["scenario"] == sc.name):
            n = mrow["trials"]
            t.add_row(
                "all",
                mrow["method"],
                _fmt(mrow["avg_iterations"], "{:.1f}"),
                "",
                f"{mrow['reached']}/{n}",
                f"{mrow['collision_free']}/{n}",
                "",
                f"{100 * mrow['safe_rate']:.0f}",
                _fmt(mrow["paper_safe_rate"], "{:.0%}").rstrip("%"),
                "",
            )
        mine = [x for x in methods if x["scenario"] == sc.name]
        if mine and mine[0]["order_fsfm_sfm_apf_holds"] is not None:
            word = {True: "holds", False: "does NOT hold"}
            t.caption = (
                f"F-SFM >= SFM >= APF: safe rate {word[mine[0]['order_fsfm_sfm_apf_holds']]}, "
                f"collision-free rate {word[mine[0]['order_holds_collision_free']]}"
            )
        console.print(t)

    tm = timing(r)
    t = Table(title="compute time per iteration (medians over every iteration of every trial)", title_justify="left")
    t.add_column("method")
    t.add_column(r"navigator step \[us]", justify="right")
    t.add_column(r"whole iteration \[us]", justify="right")
    for m in METHODS:
        if m in tm["step_us_median"]:
            t.add_row(m, _fmt(tm["step_us_median"][m], "{:.2f}"), _fmt(tm["iteration_us_median"][m], "{:.1f}"))
    if "fis_overhead_step_percent" in tm:
        t.add_section()
        t.add_row(
            "F-SFM over SFM",
            f"{tm['fis_overhead_step_percent']:+.1f} %",
            f"{tm['fis_overhead_iteration_percent']:+.1f} %",
        )
        t.add_row("paper 1 (whole iteration)", "", f"{PAPER_SFM_MS} -> {PAPER_FSFM_MS} ms, +{PAPER_FIS_OVERHEAD} %")
    if "fsfm_within_budget" in tm:
        t.caption = (
            f"F-SFM step median {'within' if tm['fsfm_within_budget'] else 'OVER'} the {FSFM_BUDGET_US:g} us budget"
        )
    console.print(t)

    if r.spec.local_minima:
        t = Table(title="paper 3 local minima, E-puck (differential drive), one run each", title_justify="left")
        for col in (
            "env",
            "method",
            "reached",
            "time [s]",
            "path [m]",
            "paper path [m]",
            "min clearance [m]",
            "min centre dist [m]",
            "final dist to goal [m]",
            "contacts",
        ):
            t.add_column(escape(col), justify="left" if col in ("env", "method") else "right")
        for row in minima_rows(r):
            t.add_row(
                row["env"],
                row["method"],
                "yes" if row["reached"] else "no",
                f"{row['time_s']:.1f}",
                f"{row['path_length_m']:.3f}",
                _fmt(row["paper_path_length_m"], "{:.2f}"),
                f"{row['min_clearance_m']:.3f}",
                f"{row['min_centre_distance_m']:.3f}",
                f"{row['final_distance_to_goal_m']:.3f}",
                str(row["collisions"]),
            )
        console.print(t)


def _fmt(v: Any, pattern: str) -> str:
    return "-" if v is None else pattern.format(v)
