"""Reading a scenario file a stranger may have written: bounded before it is parsed.

A scenario file is data, and hostile data must end in one line, never in a
hang, a traceback or gigabytes: only a regular file is opened (a FIFO or a
device would block the reader), at most `MAX_BYTES` of it, as UTF-8 text, its
brackets nested at most `MAX_DEPTH` deep (the TOML parser recurses once per
level), and its tables counted (`MAX_SCENARIOS`, `MAX_STEPS`, `MAX_EXPECTS`).
Every problem is a `ValueError` with the reason; the loader puts the file's
name in front."""

from __future__ import annotations

import os
import re
import stat
import tomllib

MAX_BYTES = 1 << 20  # [bytes] a scenario file; the library's largest is about 2 kB
MAX_DEPTH = 16  # brackets and braces nested in one value
MAX_SCENARIOS = 200  # per file
MAX_STEPS = 2000  # per scenario (a replay with substitution makes its own steps, not counted here)
MAX_EXPECTS = 200  # per scenario

# Strings and comments skipped, so that a bracket inside them does not count.
_TOKENS = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:\\.|[^"\\\n])*"|\'[^\'\n]*\'|#[^\n]*|[\[\]{}]')


def regular_file(path: str, what: str = "file") -> None:
    """Refuse what is not a regular file (a FIFO, a socket, a device: reading it could block for good)."""
    try:
        st = os.stat(path)
    except OSError as exc:
        raise ValueError(f"cannot read it: {exc.strerror or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        raise ValueError(f"is a directory, not a {what}")
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"not a regular file (a FIFO, socket or device), refused as a {what}")


def read_text(path: str) -> str:
    """The file's text: a regular file of at most MAX_BYTES, in UTF-8."""
    regular_file(path, "scenario file")
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"cannot read it: {exc.strerror or exc}") from None
    if len(raw) > MAX_BYTES:
        raise ValueError(f"larger than {MAX_BYTES // 1024} KiB; a scenario file is a few kB")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"not UTF-8 text (byte {exc.start})") from None


def nesting(text: str) -> int:
    """The deepest nesting of brackets and braces outside strings and comments (linear time)."""
    depth = deepest = 0
    for m in _TOKENS.finditer(text):
        c = m.group()
        if c in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif c in "]}":
            depth = max(0, depth - 1)
    return deepest


def parse(text: str) -> dict:
    """TOML to a dict, refusing deep nesting before the parser's recursion meets it."""
    if nesting(text) > MAX_DEPTH:
        raise ValueError(f"brackets nested deeper than {MAX_DEPTH}; a scenario file needs 3")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"not TOML: {exc}") from None
    except RecursionError:
        raise ValueError(f"brackets nested deeper than {MAX_DEPTH}; a scenario file needs 3") from None


def check_counts(data: dict) -> None:
    """Bound the tables before they are converted: scenarios per file, steps and expectations per scenario."""
    scenarios = data.get("scenario")
    if not isinstance(scenarios, list):
        return
    if len(scenarios) > MAX_SCENARIOS:
        raise ValueError(f"scenario: {len(scenarios)} scenarios; at most {MAX_SCENARIOS} in one file")
    for i, sc in enumerate(scenarios):
        if not isinstance(sc, dict):
            continue
        for key, most in (("step", MAX_STEPS), ("expect", MAX_EXPECTS)):
            items = sc.get(key)
            if isinstance(items, list) and len(items) > most:
                raise ValueError(f"scenario[{i}].{key}: {len(items)} of them; at most {most}")


def misplaced(data: dict) -> str:
    """A file whose keys belong in a `[[scenario]]` table but stand at the top: say so."""
    from arena.scenarios.model import ScenarioSpec

    keys = [k for k in data if k in ScenarioSpec.__struct_encode_fields__]
    if not keys:
        if "scenario" not in data:
            return "no [[scenario]] table; a scenario file holds one or more (docs/scenarios.md)"
        if isinstance(data["scenario"], dict) and "name" in data["scenario"]:
            return "scenario: write [[scenario]] (two brackets: a file may hold several), not [scenario]"
        return ""
    return (
        f"{', '.join(f'`{k}`' for k in keys)} belong in a [[scenario]] table: "
        "put the line [[scenario]] above them (docs/scenarios.md)"
    )
