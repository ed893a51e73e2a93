"""What `arena experiment tune` leaves in `--out`: history.csv, result.json, trace.png, report.md."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from arena.experiments.fixtures import write_atomic


def play_command(strategy: str, best: dict) -> str:
    flags = " ".join(f"--param a.{k}={v}" for k, v in best.items())
    return f"arena match --home {strategy} --away OPPONENT {flags}"


def write_history(out: Path, state: dict, names: list[str]) -> None:
    rows = state["iterations"]
    with open(out / "history.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        spsa = bool(rows) and "y_plus" in rows[0]
        w.writerow(["iteration", *(["points_plus", "points_minus"] if spsa else ["points"]), *names])
        for r in rows:
            ys = [r["y_plus"], r["y_minus"]] if spsa else [r["y"]]
            w.writerow([r["k"] + 1, *ys, *(r["values"].get(n, "") for n in names)])


def plot_trace(out: Path, state: dict, space) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = state["iterations"]
    numeric = [p for p in space.params if p.type in ("int", "float")]
    if not rows or not numeric:
        return
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ks = [r["k"] + 1 for r in rows]
    for p in numeric:
        top.plot(ks, [(r["values"][p.name] - p.low) / (p.high - p.low) for r in rows], label=p.name)
    top.set_ylabel("value (0 = low, 1 = high)")
    top.legend(fontsize="small")
    if "y_plus" in rows[0]:
        bottom.plot(ks, [r["y_plus"] for r in rows], ".", label="theta + c delta")
        bottom.plot(ks, [r["y_minus"] for r in rows], ".", label="theta - c delta")
    else:
        bottom.plot(ks, [r["y"] for r in rows], ".", label="trial")
    bottom.set_ylabel("points per match")
    bottom.set_xlabel("iteration")
    bottom.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(out / "trace.png", dpi=100)
    plt.close(fig)


def report(result: dict, names: list[str]) -> str:
    rm = result["remeasure"]
    lines = [
        f"# Tuning {result['strategy']} against {', '.join(result['opponents'])}",
        "",
        f"{result['method']}, {result['iterations']} iterations; the best values re-measured against the defaults "
        f"on fresh seeds {rm['seeds'][0]}-{rm['seeds'][1]} ({rm['matches']} matches, each seed with both ends).",
        "",
        "| parameter | default | best |",
        "|---|---|---|",
        *(f"| {n} | {result['defaults'][n]} | {result['best'][n]} |" for n in names),
        "",
        f"Points per match: best {rm['best_points']:.3f}, defaults {rm['default_points']:.3f}; "
        f"gain **{rm['gain']:+.3f}** (95 % interval {rm['ci95'][0]:+.3f} to {rm['ci95'][1]:+.3f}, "
        "bootstrap over seeds, paired).",
        f"Goal difference per match: best {rm['best_goal_diff']:+.3f}, defaults {rm['default_goal_diff']:+.3f}.",
        "",
        f"Play it: `{play_command(result['strategy'], result['best'])}`",
        "",
        "![the tuned values and the points per iteration](trace.png)",
        "",
    ]
    return "\n".join(lines)


def write_outputs(opts, space, state: dict, result: dict) -> None:
    names = [p.name for p in space.params]
    write_history(opts.out, state, names)
    write_atomic(opts.out / "result.json", json.dumps(result, indent=1))
    plot_trace(opts.out, state, space)
    write_atomic(opts.out / "report.md", report(result, names))
