"""`arena bench nav`: the navigators against the experiments of their papers.

* **Paper 1** (Dewantara, Ariyadi and Oktavianto 2021, Section 3, Tables 3-6):
  the Robotino among two opponents, in three scenario families (static,
  crossing, pursuing), with the schemes of Table 3 (SFM k = 100 and 300, APF
  zeta = 100 and 300, F-SFM with two output-set schemes) plus MAPF. Each
  scheme runs `trials` trials that differ by seeded noise; reported per scheme:
  average iterations to the target, collision-free trials, % safe navigation,
  next to the paper's numbers.
* **Compute time**: the median wall time of one navigator call per method, of
  one whole iteration, and F-SFM's overhead over SFM (paper 1 Section 3.3:
  +9.05 %).
* **Paper 3** (Puriyanto et al., Section III-B, Table I): the E-puck in the
  SAROG and GNRON local minima with APF and MAPF: reached, path length,
  minimum clearance.

Everything is stepped in this process through the engine's own robot model:
`sim/physics/` (pymunk bodies driven through `sim/drive.py`'s
wheels, the same code a match runs) and `sim/sensors.py` for perception.
The robot is team a's robot 0; the obstacles are team b's robots, opponents of
the same model, driven by scripted commands. A collision is the engine's own
robot-robot contact event (FOUL_PUSHING with the pushing threshold at -inf, so
every contact counts).

Scenario definitions are data: `navbench.toml` in this package, or a
user's file (`--scenarios FILE`). The parameters live there, not here.
Every random number comes from one numpy Generator per trial, seeded from
(seed, scenario, trial) and shared by every scheme (common random numbers), so
the same seed gives the same results; only the wall-clock timings differ.

One module per concern: `spec.py` (the file's schema), `loader.py` and
`checks.py` (reading and checking it), `trials.py` and `minima.py` (the
experiments), `metrics.py`, `report.py` and `console.py` (the results as
rows and tables), `plots.py` (trajectory plots), `run.py` (the bench and
`arena bench nav`).
"""

from arena.experiments.navbench.console import print_report
from arena.experiments.navbench.loader import builtin_text, load
from arena.experiments.navbench.minima import run_local_minimum
from arena.experiments.navbench.plots import write_plots
from arena.experiments.navbench.report import Report, method_rows, minima_rows, results_rows, timing
from arena.experiments.navbench.run import main, run_bench, select, work_units
from arena.experiments.navbench.spec import BenchSpec, LocalMinimum, Scenario, ScenarioError, Scheme
from arena.experiments.navbench.trials import Trial, run_trial, trial_rng

__all__ = [
    "BenchSpec",
    "LocalMinimum",
    "Report",
    "Scenario",
    "ScenarioError",
    "Scheme",
    "Trial",
    "builtin_text",
    "load",
    "main",
    "method_rows",
    "minima_rows",
    "print_report",
    "results_rows",
    "run_bench",
    "run_local_minimum",
    "run_trial",
    "select",
    "timing",
    "trial_rng",
    "work_units",
    "write_plots",
]
