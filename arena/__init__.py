"""soccer-arena: wheeled-robot soccer as separate OS processes over zenoh.

The repository keeps `runtime/`, `processes/`, `schemas/`, `tools/` and
`strategies/` at its top; they install as `arena.runtime`, `arena.processes`,
and so on (see pyproject.toml).
"""

__version__ = "0.1.0"
