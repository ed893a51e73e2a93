"""PNG trajectory plots in the manner of paper 1 Figs. 7-9 and paper 3 Figs. 7-8 (`--plots DIR`)."""

from __future__ import annotations

from pathlib import Path

from arena.experiments.navbench.metrics import _safe
from arena.experiments.navbench.report import Report
from arena.experiments.navbench.spec import METHODS, Scheme

METHOD_COLOURS = {"apf": "tab:red", "sfm": "tab:orange", "f-sfm": "goldenrod", "mapf": "tab:purple"}


def write_plots(r: Report, out_dir: str | Path) -> list[Path]:  # noqa: PLR0915 - one figure per table of the papers
    """PNG trajectory plots in the manner of paper 1 Figs. 7-9 and paper 3 Figs. 7-8; returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for sc in r.spec.scenarios:
        first: dict[str, Scheme] = {}
        for scheme in sc.schemes:
            first.setdefault(scheme.method, scheme)
        panels = [first[m] for m in METHODS if m in first]
        fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 4.4), squeeze=False)
        half = sc.robot.size / 2
        for ax, scheme in zip(axes[0], panels):
            trials = r.runs[(sc.name, scheme.name)]
            for k, t in enumerate(trials):
                if k > 0:
                    ax.plot(t.robot_xy[:, 0], t.robot_xy[:, 1], color="gold", lw=0.8, alpha=0.45)
                    for j in range(t.obstacles_xy.shape[1]):
                        ax.plot(t.obstacles_xy[:, j, 0], t.obstacles_xy[:, j, 1], color="tab:blue", lw=0.5, alpha=0.2)
            t0 = trials[0]
            for j in range(t0.obstacles_xy.shape[1]):
                ax.plot(t0.obstacles_xy[:, j, 0], t0.obstacles_xy[:, j, 1], color="tab:blue", lw=1.6)
                ax.add_patch(Circle(tuple(t0.obstacles_xy[0, j]), half, fc="tab:blue", alpha=0.25, ec="tab:blue"))
                ax.add_patch(Circle(tuple(t0.obstacles_xy[-1, j]), half, fc="none", ec="tab:blue", ls="--"))
            ax.plot(t0.robot_xy[:, 0], t0.robot_xy[:, 1], color="darkgoldenrod", lw=2.0, label="robot, trial 1")
            ax.add_patch(Circle(tuple(t0.robot_xy[-1]), half, fc="none", ec="darkgoldenrod"))
            hits = [p for t in trials for p in t.collision_xy]
            if hits:
                ax.scatter(
                    [p[0] for p in hits], [p[1] for p in hits], marker="x", color="red", s=30, zorder=5, label="contact"
                )
            ax.plot(*sc.spec.start, "ko", ms=5)
            ax.plot(*sc.spec.target, marker="*", color="green", ms=14, ls="none", label="target")
            safe = sum(_safe(t) for t in trials)
            ax.set_title(f"{scheme.name} {scheme.label}\nsafe {safe}/{len(trials)}", fontsize=9)
            ax.set_aspect("equal")
            ax.set_xlim(sc.spec.start[0] - 0.7, sc.spec.target[0] + 1.0)
            ax.set_ylim(-2.3, 2.3)
            ax.grid(alpha=0.3)
            ax.set_xlabel("x [m]")
        axes[0][0].set_ylabel("y [m]")
        axes[0][0].legend(loc="lower left", fontsize=7)
        fig.suptitle(f"{sc.name}: {sc.spec.title} (yellow: robot, blue: obstacles; bold: trial 1)", fontsize=10)
        fig.tight_layout()
        path = out / f"nav_{_slug(sc.name)}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)

    if r.spec.local_minima:
        n = len(r.spec.local_minima)
        fig, axes = plt.subplots(1, n, figsize=(5.5 * n, 4.2), squeeze=False)
        for ax, lm in zip(axes[0], r.spec.local_minima):
            half = lm.robot.size / 2
            for ox, oy in lm.spec.obstacles:
                ax.add_patch(Circle((ox, oy), half, fc="tab:blue", alpha=0.5))
                for _method, params in lm.methods:
                    r_safe = getattr(params, "safe_distance", None)
                    if r_safe:
                        ax.add_patch(Circle((ox, oy), r_safe, fc="none", ec="grey", ls=":"))
                        break
            for method, _ in lm.methods:
                t = r.minima[(lm.name, method)]
                ax.plot(
                    t.robot_xy[:, 0],
                    t.robot_xy[:, 1],
                    color=METHOD_COLOURS.get(method, "k"),
                    lw=1.6,
                    label=f"{method}: {'reached' if t.reached else 'not reached'}, {t.path_length:.2f} m",
                )
            ax.plot(*lm.spec.start, "ko", ms=5)
            ax.plot(*lm.spec.goal, marker="*", color="green", ms=14, ls="none")
            ax.set_title(f"{lm.name}: {lm.spec.title}", fontsize=9)
            ax.set_aspect("equal")
            ax.grid(alpha=0.3)
            ax.set_xlabel("x [m]")
            ax.legend(fontsize=7, loc="upper left")
        axes[0][0].set_ylabel("y [m]")
        fig.suptitle("paper 3 local minima, E-puck (dotted: safe distance r of APF/MAPF)", fontsize=10)
        fig.tight_layout()
        path = out / "nav_local_minima.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)
