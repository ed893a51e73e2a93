"""What `arena experiment run` writes once its matches are in: the tidy rows (rows.csv,
rows.json), per cell the mean of each response with its 95 % bootstrap interval (a
scenario's `pass`: the pass rate with its Wilson interval, as `arena scenario run` gives it)
(summary.json), a plot per response (plots/<response>.png) and report.md.

The interval is over seeds: a seed's value is its matches' mean (both ends, every
opponent), and the seeds are resampled with replacement (a percentile bootstrap, 2000
resamples from a fixed seed, so a rerun writes the same numbers). Every cell plays the same
seeds (common random numbers), so a cell's difference to its reference cell is resampled by
seed too, the pair kept together (`diff` in summary.json and the report). A cell's reference
is the first cell with the same values of every factor but the last one in the file: over
one factor the first cell, over latency per strategy (`home`, then the latency) the same
strategy at the first latency.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from arena.experiments import experiment_standings
from arena.experiments.design import PASS, Experiment
from arena.experiments.fixtures import write_atomic
from arena.experiments.ratings import wilson

RESAMPLES = 2000
BOOT_SEED = 20_260_101  # the bootstrap's own seed: the same intervals on every rerun
ROW_KEYS_LAST = ("digest", "cpu_s", "attempts", "reason")


def per_seed(exp: Experiment, rows: list[dict], cell: str, response: str) -> dict[int, float]:
    """A cell's response per seed: the mean over that seed's matches (both ends, every opponent)."""
    got: dict[int, list[float]] = {}
    for r in rows:
        if r["cell"] == cell and r["status"] == "ok" and response in r:
            got.setdefault(r["seed"], []).append(float(r[response]))
    return {s: float(np.mean(v)) for s, v in got.items()}


def bootstrap(values: np.ndarray, idx: np.ndarray) -> tuple[float, float, float]:
    """(mean, low, high): the 95 % percentile interval of the mean over resamples `idx` (rows of indices)."""
    if len(values) == 0:
        return (float("nan"),) * 3
    means = values[idx].mean(axis=1)
    lo, hi = np.percentile(means, [2.5, 97.5])
    return float(values.mean()), float(lo), float(hi)


def reference(exp: Experiment, c: int) -> int:
    """The cell `c` is compared with: the first with the same values of every factor but the last."""
    keep = [f.path for f in exp.factors[:-1]]
    mine = exp.cells[c]
    return next(j for j, other in enumerate(exp.cells) if all(other[k] == mine[k] for k in keep))


def summarise(exp: Experiment, rows: list[dict]) -> dict:
    """Per cell and response: mean, 95 % interval, and the seed-paired difference to its reference cell."""
    rng = np.random.default_rng(BOOT_SEED)
    seeds = exp.seeds
    idx = rng.integers(0, len(seeds), size=(RESAMPLES, len(seeds)))  # the same resamples in every cell: paired
    cells = []
    full_values: dict[tuple[int, str], np.ndarray] = {}  # (cell, response) -> per seed, when every seed played
    for c, cell in enumerate(exp.cells):
        name = f"c{c:03d}"
        ref = reference(exp, c)
        out = {"cell": name, **cell, "strategy": exp.configs[c].home, "matches": 0, "failed": 0}
        out["matches"] = sum(1 for r in rows if r["cell"] == name and r["status"] == "ok")
        out["failed"] = sum(1 for r in rows if r["cell"] == name and r["status"] != "ok")
        if ref != c:
            out["reference"] = f"c{ref:03d}"
        for resp in exp.responses:
            by_seed = per_seed(exp, rows, name, resp)
            full = len(by_seed) == len(seeds)
            v = np.array([by_seed[s] for s in seeds]) if full else np.array(list(by_seed.values()))
            own_idx = idx if full else rng.integers(0, max(1, len(v)), size=(RESAMPLES, max(1, len(v))))
            mean, lo, hi = bootstrap(v, own_idx)
            if resp == PASS:  # a pass rate: the Wilson interval over the runs, as arena scenario run's
                runs = [int(r[resp]) for r in rows if r["cell"] == name and r["status"] == "ok" and resp in r]
                mean, (lo, hi) = (sum(runs) / len(runs) if runs else float("nan")), wilson(sum(runs), len(runs))
            out[resp] = {"mean": _r(mean), "low": _r(lo), "high": _r(hi), "seeds": len(v)}
            if full:
                full_values[(c, resp)] = v
            if ref != c and full and (ref, resp) in full_values:
                d_mean, d_lo, d_hi = bootstrap(v - full_values[(ref, resp)], idx)
                out[resp]["diff"] = {"mean": _r(d_mean), "low": _r(d_lo), "high": _r(d_hi)}
        cells.append(out)
    return {
        "name": exp.name,
        "factors": [f.path for f in exp.factors],
        "responses": exp.responses,
        "seeds": seeds,
        "opponents": exp.opponents,
        "design": exp.design,
        "matches": len(rows),
        "failed": sum(1 for r in rows if r["status"] != "ok"),
        "cells": cells,
    }


def _r(x: float) -> float | None:
    return None if x != x else round(x, 4)  # NaN: no value


def write(exp: Experiment, rows: list[dict], out: Path) -> dict:
    """rows.csv, rows.json, summary.json, plots/*.png and report.md into `out`; returns the summary."""
    keys: list[str] = []
    for r in rows:
        keys += [k for k in r if k not in keys and k not in ROW_KEYS_LAST]
    keys += [k for k in ROW_KEYS_LAST if any(k in r for r in rows)]
    with open(out / "rows.csv.tmp", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, restval="")
        w.writeheader()
        w.writerows(rows)
    (out / "rows.csv.tmp").replace(out / "rows.csv")
    write_atomic(out / "rows.json", json.dumps(rows, indent=1))
    summary = summarise(exp, rows)
    rounds = experiment_standings.build(exp, rows)  # a round robin per setting: Table 2
    if rounds:
        summary["standings"] = rounds
    write_atomic(out / "summary.json", json.dumps(summary, indent=1))
    plots = plot_all(exp, summary, out / "plots") if rows else []
    text = report(exp, summary, plots) + "\n".join(experiment_standings.markdown(rounds)) + ("\n" if rounds else "")
    write_atomic(out / "report.md", text)
    table2 = experiment_standings.plot(rounds, out / "plots")
    summary["plots"] = [str(p) for p in plots] + ([str(table2)] if table2 else [])
    return summary


# --------------------------------------------------------------------- plots
def varying(exp: Experiment) -> list[str]:
    """The factors that take more than one value over the cells, in the file's order."""
    return [f.path for f in exp.factors if len({repr(c[f.path]) for c in exp.cells}) > 1]


def _numeric(values) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def plot_all(exp: Experiment, summary: dict, folder: Path) -> list[Path]:
    """One PNG per response: a line with its band over one factor; over two, a line per level of a
    factor of names (strategies) or a heatmap; nothing for none or more than two."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    vary = varying(exp)
    if not 1 <= len(vary) <= 2:
        return []
    folder.mkdir(exist_ok=True)
    made = []
    for resp in exp.responses:
        fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=110)
        if len(vary) == 1:
            _lines(ax, summary["cells"], vary[0], None, resp)
        else:
            x, y = vary
            xs, ys = [c[x] for c in summary["cells"]], [c[y] for c in summary["cells"]]
            if not _numeric(xs) and _numeric(ys):
                x, y = y, x
                xs, ys = ys, xs
            if _numeric(xs) and not _numeric(ys):
                _lines(ax, summary["cells"], x, y, resp)
            else:
                _heatmap(fig, ax, summary["cells"], x, y, resp)
        ax.set_title(f"{exp.name}: {resp} (mean, 95 % interval over {len(exp.seeds)} seeds)", fontsize=9)
        fig.tight_layout()
        path = folder / f"{resp}.png"
        fig.savefig(path)
        plt.close(fig)
        made.append(path)
    return made


def _lines(ax, cells: list[dict], x: str, group: str | None, resp: str) -> None:
    groups: dict = {}
    for c in cells:
        groups.setdefault(c[group] if group else "", []).append(c)
    for name, members in groups.items():
        members.sort(key=lambda c: c[x] if _numeric([c[x]]) else str(c[x]))
        xs = [c[x] for c in members]
        pos = xs if _numeric(xs) else list(range(len(xs)))
        mean, lo, hi = ([_nan(c[resp][k]) for c in members] for k in ("mean", "low", "high"))
        ax.plot(pos, mean, marker="o", label=_short(name) if group else None)
        ax.fill_between(pos, lo, hi, alpha=0.2)
        if not _numeric(xs):
            ax.set_xticks(pos, [_short(v) for v in xs])
    ax.set_xlabel(x)
    ax.set_ylabel(resp)
    ax.grid(alpha=0.3)
    if group:
        ax.legend(title=group, fontsize=8)


def _heatmap(fig, ax, cells: list[dict], x: str, y: str, resp: str) -> None:
    """The mean per cell in colour, written in each cell with its interval."""
    order = lambda v: (not _numeric([v]), v if _numeric([v]) else str(v))
    xs, ys = sorted({c[x] for c in cells}, key=order), sorted({c[y] for c in cells}, key=order)
    grid = np.full((len(ys), len(xs)), np.nan)
    text = {}
    for c in cells:
        i, j = ys.index(c[y]), xs.index(c[x])
        grid[i, j] = _nan(c[resp]["mean"])
        if c[resp]["mean"] is not None:
            text[i, j] = f"{c[resp]['mean']:.2f}\n[{c[resp]['low']:.2f}, {c[resp]['high']:.2f}]"
    im = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis")
    ax.set_xticks(range(len(xs)), [_short(v) for v in xs])
    ax.set_yticks(range(len(ys)), [_short(v) for v in ys])
    for (i, j), label in text.items():  # dark text on the light end of the colour map
        ax.text(j, i, label, ha="center", va="center", fontsize=7, color="k" if im.norm(grid[i, j]) > 0.6 else "w")
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    fig.colorbar(im, ax=ax, label=resp)


def _nan(x: float | None) -> float:
    return float("nan") if x is None else x


def _short(v) -> str:
    from arena.experiments.fixtures import short

    return short(v) if isinstance(v, str) else f"{v:g}" if _numeric([v]) else str(v)


# -------------------------------------------------------------------- report
def report(exp: Experiment, summary: dict, plots: list[Path]) -> str:
    """report.md: what was played, the table of means with intervals, the plots."""
    lines = [f"# Experiment {exp.name}", ""]
    sc = exp.scenario
    played = f"runs of scenario {sc.name!r} ({sc.path})" if sc is not None else "matches"
    ends = "one run per cell and seed" if sc is not None else "each played with the ends swapped"
    lines.append(
        f"`arena experiment run {exp.path}`: {summary['matches']} {played} ({summary['failed']} failed), "
        f"{len(exp.cells)} cells ({exp.design} design), seeds {exp.seeds[0]}..{exp.seeds[-1]}, "
        f"{ends}; engine {exp.engine}."
    )
    if exp.opponents:
        lines.append(f"Opponents: {', '.join(exp.opponents)} (each cell's strategy against each of the others).")
    wilson_note = "; `pass`: the pass rate with its 95 % Wilson interval" if PASS in exp.responses else ""
    lines += [
        "",
        f"Mean per cell with its 95 % bootstrap interval over seeds{wilson_note}; Δ: the difference to the "
        "reference cell (the first with the same values of every factor but the last), paired by seed.",
        "",
    ]
    head = ["cell", *[f.path for f in exp.factors], "strategy", "matches", *exp.responses]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for c in summary["cells"]:
        vals = [c["cell"], *[_short(c[f.path]) for f in exp.factors], _short(c["strategy"]), str(c["matches"])]
        for resp in exp.responses:
            s = c[resp]
            text = "-" if s["mean"] is None else f"{s['mean']:.2f} [{s['low']:.2f}, {s['high']:.2f}]"
            if "diff" in s:
                text += f" (Δ {s['diff']['mean']:+.2f} [{s['diff']['low']:+.2f}, {s['diff']['high']:+.2f}])"
            vals.append(text)
        lines.append("| " + " | ".join(vals) + " |")
    if plots:
        lines += [""] + [f"![{p.stem}](plots/{p.name})" for p in plots]
    return "\n".join(lines) + "\n"
