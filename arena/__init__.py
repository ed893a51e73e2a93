"""soccer-arena: wheeled-robot soccer as separate OS processes over zenoh.

Every top-level folder of the repository installs under this one import root:
`arena.x.y` is `x/y.py` (`arena.sim.drive` is sim/drive.py); see
pyproject.toml and docs/architecture.md for the package map.
"""

__version__ = "0.1.0"
