"""The rich Console every printer of the `arena` commands uses.

On a terminal it takes the terminal's width. Piped or redirected, rich would
wrap at 80 columns (`...engine \\nprocesses`, `digest \\nb14fc08017586ca8`),
which breaks grep and logs: there every line is printed whole instead. A
`COLUMNS` set in the environment still wins. `--json` stays the interface for
programs; this keeps the text readable by people's tools too.
"""

from __future__ import annotations

import os
import sys

from rich.console import Console

PIPED_WIDTH = 10_000  # [columns] wider than any line we print: nothing wraps


def console(stderr: bool = False) -> Console:
    """A Console on stdout (or stderr) that never wraps when that stream is not a terminal."""
    stream = sys.stderr if stderr else sys.stdout
    piped = not stream.isatty() and "COLUMNS" not in os.environ
    return Console(stderr=stderr, width=PIPED_WIDTH if piped else None)
