"""The bench's results as rows: per scheme, per method, timing and local minima; `Report.to_json` for `--json`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from arena.experiments.navbench.metrics import _avg_iterations, _free, _median_us, _ordered, _safe
from arena.experiments.navbench.spec import (
    FSFM_BUDGET_US,
    METHODS,
    PAPER_FIS_OVERHEAD,
    PAPER_FSFM_MS,
    PAPER_SFM_MS,
    BenchSpec,
)
from arena.experiments.navbench.trials import Trial


@dataclass
class Report:
    seed: int
    trials: int
    source: str
    runs: dict[tuple[str, str], list[Trial]]  # (scenario, scheme) -> trials
    minima: dict[tuple[str, str], Trial]  # (env, method) -> run
    spec: BenchSpec

    def to_json(self) -> dict[str, Any]:
        return {
            "seed": self.seed,
            "trials": self.trials,
            "scenarios": self.source,
            "definitions": {
                "safe": "reached the target within the time limit without touching an obstacle",
                "collision_free": "never touched an obstacle (paper 1's 'free collision')",
                "avg_iterations": "mean navigator calls until the target was reached, over the trials that reached it",
                "us_per_iteration": "median wall time of one navigator call [us]",
                "iteration_us": "median wall time of one whole iteration: perception, navigator, engine tick [us]",
                "min_clearance_m": "smallest centre distance minus the robot size, the gap between two round "
                "footprints; the engine's robots are boxes, so corners can touch at up to 0.41 x size",
            },
            "results": results_rows(self),
            "methods": method_rows(self),
            "timing": timing(self),
            "mapf": minima_rows(self),
        }


def results_rows(r: Report) -> list[dict[str, Any]]:
    rows = []
    for sc in r.spec.scenarios:
        for scheme in sc.schemes:
            ts = r.runs[(sc.name, scheme.name)]
            ref = sc.spec.reference.get(scheme.name)
            rows.append(
                {
                    "scenario": sc.name,
                    "method": scheme.method,
                    "scheme": scheme.name,
                    "label": scheme.label,
                    "trials": len(ts),
                    "reached": sum(t.reached for t in ts),
                    "collision_free": sum(_free(t) for t in ts),
                    "safe": sum(_safe(t) for t in ts),
                    "safe_rate": round(sum(_safe(t) for t in ts) / len(ts), 4),
                    "collision_free_rate": round(sum(_free(t) for t in ts) / len(ts), 4),
                    "avg_iterations": _avg_iterations(ts),
                    "us_per_iteration": _median_us(n for t in ts for n in t.nav_ns),
                    "iteration_us": _median_us(n for t in ts for n in t.iter_ns),
                    "min_clearance_m": round(min(t.min_clearance for t in ts), 4),
                    "paper_avg_iterations": ref.iterations if ref else None,
                    "paper_collision_free": ref.free if ref else None,
                    "paper_safe_rate": round(ref.free / 10, 4) if ref else None,
                }
            )
    return rows


def method_rows(r: Report) -> list[dict[str, Any]]:
    """Per scenario and method, both schemes pooled (as paper 1's "Avg. All" columns), and the ordering check."""
    out = []
    for sc in r.spec.scenarios:
        pooled: dict[str, list[Trial]] = {}
        paper: dict[str, list[int]] = {}
        for scheme in sc.schemes:
            pooled.setdefault(scheme.method, []).extend(r.runs[(sc.name, scheme.name)])
            ref = sc.spec.reference.get(scheme.name)
            if ref:
                paper.setdefault(scheme.method, []).append(ref.free)
        rates = {m: sum(_safe(t) for t in ts) / len(ts) for m, ts in pooled.items()}
        free = {m: sum(_free(t) for t in ts) / len(ts) for m, ts in pooled.items()}
        ordered, ordered_free = _ordered(rates), _ordered(free)
        for m in METHODS:
            if m not in pooled:
                continue
            ts = pooled[m]
            out.append(
                {
                    "scenario": sc.name,
                    "method": m,
                    "trials": len(ts),
                    "safe": sum(_safe(t) for t in ts),
                    "collision_free": sum(_free(t) for t in ts),
                    "reached": sum(t.reached for t in ts),
                    "safe_rate": round(rates[m], 4),
                    "collision_free_rate": round(free[m], 4),
                    "avg_iterations": _avg_iterations(ts),
                    "paper_safe_rate": round(sum(paper[m]) / (10 * len(paper[m])), 4) if m in paper else None,
                    "order_fsfm_sfm_apf_holds": ordered,
                    "order_holds_collision_free": ordered_free,
                }
            )
    return out


def timing(r: Report) -> dict[str, Any]:
    nav: dict[str, list[int]] = {}
    loop: dict[str, list[int]] = {}
    for sc in r.spec.scenarios:
        for scheme in sc.schemes:
            for t in r.runs[(sc.name, scheme.name)]:
                nav.setdefault(scheme.method, []).extend(t.nav_ns)
                loop.setdefault(scheme.method, []).extend(t.iter_ns)
    step_us = {m: _median_us(v) for m, v in nav.items()}
    iter_us = {m: _median_us(v) for m, v in loop.items()}
    out: dict[str, Any] = {"step_us_median": step_us, "iteration_us_median": iter_us}
    if step_us.get("sfm") and step_us.get("f-sfm"):
        out["fis_overhead_step_percent"] = round(100.0 * (step_us["f-sfm"] / step_us["sfm"] - 1.0), 1)
        out["fis_overhead_iteration_percent"] = round(100.0 * (iter_us["f-sfm"] / iter_us["sfm"] - 1.0), 1)
    if step_us.get("f-sfm") is not None:
        out["fsfm_within_budget"] = step_us["f-sfm"] <= FSFM_BUDGET_US
    out["paper"] = {"sfm_ms": PAPER_SFM_MS, "fsfm_ms": PAPER_FSFM_MS, "fis_overhead_percent": PAPER_FIS_OVERHEAD}
    return out


def minima_rows(r: Report) -> list[dict[str, Any]]:
    rows = []
    for lm in r.spec.local_minima:
        for method, _ in lm.methods:
            t = r.minima[(lm.name, method)]
            rows.append(
                {
                    "env": lm.name,
                    "method": method,
                    "reached": t.reached,
                    "path_length_m": round(t.path_length, 4),
                    "min_clearance_m": round(t.min_clearance, 4),
                    "min_centre_distance_m": round(t.min_centre_distance, 4),
                    "collisions": t.collisions,
                    "time_s": round(t.iterations * lm.spec.dt, 2),
                    "final_distance_to_goal_m": round(
                        math.hypot(lm.spec.goal[0] - t.robot_xy[-1, 0], lm.spec.goal[1] - t.robot_xy[-1, 1]), 4
                    ),
                    "paper_path_length_m": lm.spec.reference.get("path_length_m") if method == "mapf" else None,
                }
            )
    return rows
