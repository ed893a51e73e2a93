"""The installed soccer-arena's version (the source tree's when it is not installed), and its packages."""

from __future__ import annotations

# The packages below `arena` (pyproject.toml `packages`, first level): the bytecode the launcher writes
# before a match (match/launcher.py) and the source a cluster's version check hashes
# (experiments/cluster.py) cover them all. learn is hashed by path: its extra need not be installed.
PACKAGES = (
    "config",
    "runtime",
    "processes",
    "schemas",
    "review",
    "experiments",
    "match",
    "strategies",
    "navigation",
    "sim",
    "rules",
    "recording",
    "refbox",
    "scenarios",
    "learn",
    "commands",
)


def package_version() -> str:
    from importlib import metadata

    try:
        return metadata.version("soccer-arena")
    except metadata.PackageNotFoundError:
        from arena import __version__

        return __version__
