"""soccer-arena: wheeled-robot soccer as separate OS processes over zenoh.

Every top-level folder of the repository installs under this one import root:
`arena.x.y` is `x/y.py` (`arena.sim.drive` is sim/drive.py); see
pyproject.toml and docs/architecture.md for the package map.
"""

import os

# The simulation's linear algebra is on 3- and 4-element matrices, too small for OpenBLAS's threads,
# which busy-wait after each call (the drive's pseudo-inverse as a match is built: ~6 % of a 2 x 60 s
# in-process match's CPU). Matches run in parallel as processes instead. Set before numpy is imported;
# a value the user gave is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

__version__ = "0.1.0"
