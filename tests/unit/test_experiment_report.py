"""What `arena experiment run` computes from its rows (experiments/experiment_report.py):
bootstrap intervals over seeds, the difference to a reference cell paired by seed, the plots."""

from __future__ import annotations

import numpy as np

from arena.experiments import design, experiment_report


def experiment(tmp_path, factors: str, seeds: int = 8):
    p = tmp_path / "exp.toml"
    p.write_text(f'seeds = {seeds}\nresponses = ["points"]\n[base]\nhome = "AD"\naway = "BS"\n[factors]\n{factors}')
    return design.load(str(p))


def rows_of(exp, value) -> list[dict]:
    """One row per match of `exp`, its points `value(cell, seed, team)`."""
    out = []
    for m in exp.matches():
        c = f"c{m['cell']:03d}"
        out.append({"match": m["id"], "cell": c, **exp.cells[m["cell"]], "seed": m["seed"], "team": m["team"],
                    "status": "ok", "points": value(m["cell"], m["seed"], m["team"])})  # fmt: skip
    return out


def test_interval_and_the_paired_difference(tmp_path):
    exp = experiment(tmp_path, '"links.wifi.latency_ms" = [0.0, 50.0]')
    noise = np.random.default_rng(3).normal(0, 1, size=8)  # each seed's luck, shared by both cells
    rows = rows_of(exp, lambda c, s, t: 1.5 + noise[s] - 0.25 * c)
    summary = experiment_report.summarise(exp, rows)
    first, second = summary["cells"]
    assert first["points"]["low"] < first["points"]["mean"] < first["points"]["high"]
    assert abs(first["points"]["mean"] - (1.5 + noise.mean())) < 1e-3
    assert "diff" not in first["points"] and second["reference"] == "c000"
    d = second["points"]["diff"]
    assert d["mean"] == -0.25 and d["low"] == d["high"] == -0.25  # the seeds' noise cancels exactly
    width = second["points"]["high"] - second["points"]["low"]
    assert width > 1.0  # while each cell's own interval carries it
    again = experiment_report.summarise(exp, rows)
    assert again == summary  # the bootstrap has its own seed: the same figures on every rerun


def test_reference_is_the_same_other_factors_at_the_first_level_of_the_last(tmp_path):
    exp = experiment(tmp_path, 'home = ["AD", "BS"]\n"links.wifi.latency_ms" = [0.0, 50.0, 100.0]')
    assert [experiment_report.reference(exp, c) for c in range(6)] == [0, 0, 0, 3, 3, 3]


def test_plots_and_report(tmp_path):
    exp = experiment(tmp_path, 'home = ["AD", "BS"]\n"links.wifi.latency_ms" = [0.0, 50.0]', seeds=2)
    rows = rows_of(exp, lambda c, s, t: (c + s) % 4)
    summary = experiment_report.write(exp, rows, tmp_path)
    assert summary["plots"] == [str(tmp_path / "plots" / "points.png")]
    assert (tmp_path / "plots" / "points.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    report = (tmp_path / "report.md").read_text()
    assert "| c003 | BS | 50 | BS | 4 |" in report and "(Δ " in report
    assert (tmp_path / "rows.csv").read_text().splitlines()[0].startswith("match,cell,home,links.wifi.latency_ms")


def test_a_cell_without_rows_has_no_value_and_no_plot_error(tmp_path):
    exp = experiment(tmp_path, '"links.wifi.latency_ms" = [0.0, 50.0]', seeds=2)
    rows = [r for r in rows_of(exp, lambda c, s, t: 1) if r["cell"] == "c000"]
    summary = experiment_report.write(exp, rows, tmp_path)
    assert summary["cells"][1]["points"]["mean"] is None and (tmp_path / "plots" / "points.png").exists()
