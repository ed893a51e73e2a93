"""One module per `arena` sub-command: `arena/commands/<name>.py` builds its
parser (`add_parser(sub)`, with examples in its help) and turns the parsed
flags into a call of a typed function of the packages below (`run(args) -> int`,
the exit code). `arena/cli.py` only dispatches. Modules whose name starts with
`_` are shared flag groups and helpers, not commands.

Nothing outside arena/ imports this package (tests/unit/test_layering.py).
"""

from __future__ import annotations

import os

# The order of `arena --help`; a command module not listed here follows, by name.
ORDER = (
    "match",
    "run",
    "credentials",
    "up",
    "tournament",
    "experiment",
    "bench",
    "facts",
    "review",
    "replay",
    "config",
    "strategies",
    "schemas",
)


def names() -> list[str]:
    """Every sub-command: a module of this package whose name does not start with `_`.

    Read off the directory: `pkgutil.iter_modules` took ~1.2 M instructions a call, and every
    `arena` command asks twice."""
    found = {f[:-3] for d in __path__ for f in os.listdir(d) if f.endswith(".py") and not f.startswith("_")}
    return [n for n in ORDER if n in found] + sorted(found - set(ORDER))
