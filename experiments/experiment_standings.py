"""A round robin per setting: when an experiment varies `home` over strategies that are also its
opponents, every setting of the other factors is a round robin, and its standings are the
paper's Table 2 (W D L GF GA GD P, ranked as `ratings.standings` ranks them), with the coverage
ratio of robot 1 to robot 2 (Fig. 9, as `ratings.coverage` works it out) and the goals per match.

Every match is in two rows (one per cell that plays it, each from its own team's side), so a
strategy's rows are its matches, and summing them gives its standing. The result is in
summary.json (`standings`), report.md and plots/standings.png.
"""

from __future__ import annotations

from pathlib import Path

from arena.experiments.design import COVERAGE, Experiment
from arena.experiments.fixtures import short


def applies(exp: Experiment) -> bool:
    """`home` varies over at least two strategies, and each is an opponent of the others."""
    homes = {c.home for c in exp.configs}
    return any(f.path == "home" for f in exp.factors) and len(homes) > 1 and homes <= set(exp.opponents)


def setting_of(exp: Experiment, cell: dict) -> tuple:
    return tuple((f.path, cell[f.path]) for f in exp.factors if f.path != "home")


def build(exp: Experiment, rows: list[dict]) -> list[dict]:
    """Per setting: its factor values, the standings, the coverage ratios and the goals per match."""
    if not applies(exp):
        return []
    cells = {f"c{i:03d}": (setting_of(exp, c), exp.configs[i].home) for i, c in enumerate(exp.cells)}
    table: dict[tuple, dict[str, dict]] = {}
    for r in rows:
        if r.get("status") != "ok" or r["cell"] not in cells:
            continue
        setting, team = cells[r["cell"]]
        row = table.setdefault(setting, {}).setdefault(
            team, {"team": team, "W": 0, "D": 0, "L": 0, "GF": 0, "GA": 0, "matches": 0, "r1": 0.0, "r2": 0.0}
        )
        gf, ga = int(r["goals_for"]), int(r["goals_against"])
        row["GF"] += gf
        row["GA"] += ga
        row["W" if gf > ga else "D" if gf == ga else "L"] += 1
        row["matches"] += 1
        row["r1"] += float(r.get(f"{COVERAGE}1", 0.0) or 0.0)
        row["r2"] += float(r.get(f"{COVERAGE}2", 0.0) or 0.0)
    out = []
    for setting, teams in table.items():
        ranked = []
        for row in teams.values():
            n = row.pop("matches")
            r1, r2 = row.pop("r1") / n, row.pop("r2") / n
            row.update(GD=row["GF"] - row["GA"], P=3 * row["W"] + row["D"], matches=n)
            row["coverage_ratio"] = round(r1 / r2, 3) if r2 > 0 else None
            ranked.append(row)
        ranked.sort(key=lambda r: (-r["P"], -r["GD"], -r["GF"], r["team"]))
        matches = sum(r["matches"] for r in ranked) / 2  # each match is in the rows of both its teams
        goals = sum(r["GF"] for r in ranked)
        out.append(
            {
                "setting": dict(setting),
                "standings": ranked,
                "order": order(ranked),
                "matches": matches,
                "goals_per_match": round(goals / matches, 3) if matches else None,
            }
        )
    return out


def order(ranked: list[dict]) -> str:
    """`AD > AS = BD > BS`: "=" between teams the ranking cannot tell apart (points, goal difference, goals)."""
    text = short(ranked[0]["team"]) if ranked else ""
    for before, r in zip(ranked, ranked[1:]):
        same = (before["P"], before["GD"], before["GF"]) == (r["P"], r["GD"], r["GF"])
        text += (" = " if same else " > ") + short(r["team"])
    return text


def markdown(standings: list[dict]) -> list[str]:
    if not standings:
        return []
    keys = list(standings[0]["setting"])
    lines = ["", "## A round robin per setting (Table 2)", ""]
    lines.append("Order by points (then goal difference, goals); P per team; robot 1 / robot 2 coverage ratio.")
    lines.append("")
    head = [*keys, "order", "P", "robot1/robot2", "goals per match", "matches"]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for s in standings:
        rows = s["standings"]
        points = ", ".join(f"{short(r['team'])} {r['P']}" for r in rows)
        ratio = ", ".join(f"{short(r['team'])} {r['coverage_ratio']}" for r in rows)
        vals = [*(str(v) for v in s["setting"].values()), s["order"], points, ratio]
        lines.append("| " + " | ".join([*vals, str(s["goals_per_match"]), f"{s['matches']:g}"]) + " |")
    return lines + ["", "![points per team and setting](plots/standings.png)"]


def plot(standings: list[dict], folder: Path) -> Path | None:
    """Points per team, one group of bars per setting."""
    if not standings:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    teams = sorted({r["team"] for s in standings for r in s["standings"]})
    labels = [", ".join(f"{k.split('.')[-1]}={v}" for k, v in s["setting"].items()) or "all" for s in standings]
    fig, ax = plt.subplots(figsize=(max(6, 1.2 * len(standings) + 2), 4.5))
    width = 0.8 / len(teams)
    for i, t in enumerate(teams):
        ys = [next((r["P"] for r in s["standings"] if r["team"] == t), 0) for s in standings]
        ax.bar([k + i * width for k in range(len(standings))], ys, width, label=short(t))
    ax.set_xticks([k + 0.4 - width / 2 for k in range(len(standings))])
    ax.set_xticklabels(labels, rotation=30, ha="right", fontsize="small")
    ax.set_ylabel("points")
    ax.legend()
    fig.tight_layout()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "standings.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
