"""The conformance verdicts `arena strategies` prints, cached by source so a second call is quick.

The suite plays a short scripted match per strategy (1 to 40 s on a loaded host). Its verdict
depends only on the code it runs: the strategy's own package and the parts of arena the suite
exercises (`SUITE_PACKAGES`). A verdict is kept under the SHA-256 of those files' contents in
`cache_dir()` (`$XDG_CACHE_HOME/soccer-arena`, else `~/.cache/soccer-arena`) and used again
while none of them changed; `arena strategies --recheck` runs the suite anyway. A cache that
cannot be read or written is no cache: the suite runs, and nothing is said.
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
from pathlib import Path

from arena.strategies.base import Strategy

# The packages whose code a conformance run executes besides the strategy's own.
SUITE_PACKAGES = ("arena.strategies", "arena.navigation", "arena.sim", "arena.rules", "arena.schemas", "arena.runtime")
CACHE_FILE = "conformance.json"


def cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "soccer-arena"


def _package_files(module_name: str) -> list[Path]:
    """The .py files of the package `module_name` belongs to (arena's second level, else its top
    level), or the module alone when it is no package's."""
    parts = module_name.split(".")
    top = ".".join(parts[:2]) if parts[0] == "arena" else parts[0]
    try:
        path = getattr(importlib.import_module(top), "__file__", None)
    except ImportError:
        path = None
    if path is None:
        return []
    path = Path(path)
    return sorted(path.parent.rglob("*.py")) if path.name == "__init__.py" else [path]


def source_hash(strategy: Strategy) -> str:
    """SHA-256 over the suite's packages and the strategy's own package, paths and contents."""
    from arena import __version__

    files: dict[Path, None] = {}
    for name in (*SUITE_PACKAGES, strategy.make_team.__module__):
        files.update(dict.fromkeys(_package_files(name)))
    h = hashlib.sha256(__version__.encode())
    for path in sorted(files):
        h.update(str(path).encode() + b"\0")
        try:
            h.update(path.read_bytes())
        except OSError:
            h.update(b"?")
    return h.hexdigest()


def _load() -> dict:
    try:
        data = json.loads((cache_dir() / CACHE_FILE).read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _store(data: dict) -> None:
    path = cache_dir() / CACHE_FILE
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps(data, indent=1, sort_keys=True))
        tmp.replace(path)
    except OSError:
        pass


def verdict(strategy: Strategy, recheck: bool = False) -> tuple[str, bool]:
    """("passes" | "fails: <the first failed check>", whether it came from the cache)."""
    from arena.strategies import conformance

    key = source_hash(strategy)
    cache = _load()
    entry = cache.get(strategy.name)
    if not recheck and isinstance(entry, dict) and entry.get("source") == key and isinstance(entry.get("status"), str):
        return entry["status"], True
    try:
        conformance.check_all(strategy)
        status = "passes"
    except AssertionError as exc:
        status = f"fails: {(str(exc).splitlines() or ['?'])[0]}"
    cache = _load()  # another call may have stored meanwhile
    cache[strategy.name] = {"source": key, "status": status}
    _store(cache)
    return status, False
