"""Every file a doc names exists: a path in docs/*.md, README.md, schemas/README.md or pyproject.toml
that starts at one of the repository's folders (`runtime/clock.py`, `docs/tournament.md`,
`tests/integration/test_engines.py`), and every relative Markdown link, resolved from its doc."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = [
    *sorted((ROOT / "docs").glob("*.md")),
    ROOT / "README.md",
    ROOT / "schemas" / "README.md",
    ROOT / "pyproject.toml",
]
TOP = sorted(p.name for p in ROOT.iterdir() if p.is_dir() and not p.name.startswith((".", "_")) and p.name != "build")
# A path from the repository's root: a top folder, then path segments, ending in a file name with an
# extension or in "/" (a folder). Globs and placeholders (`processes/*.py`, `<name>.py`) are patterns.
ROOTED = re.compile(
    rf"(?<![\w./-])(?:{'|'.join(map(re.escape, TOP))})/(?:[\w.-]+/)*(?:[\w-]+(?:\.[a-z][a-z0-9]*)+|)(?![\w/*<{{-])"
)
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def named(text: str) -> set[str]:
    return {m.group(0) for m in ROOTED.finditer(text)}


def test_the_pattern_finds_paths_and_leaves_patterns_and_words():
    text = "see runtime/clock.py, docs/tournament.md and recording/analysis/; not processes/*.py or runs/cem/x"
    assert named(text) == {"runtime/clock.py", "docs/tournament.md", "recording/analysis/"}


def test_every_path_a_doc_names_exists():
    missing = []
    for doc in DOCS:
        text = doc.read_text()
        for path in sorted(named(text)):
            if not (ROOT / path).exists():
                missing.append(f"{doc.relative_to(ROOT)}: {path}")
        if doc.suffix == ".md":
            for target in sorted({m.group(1) for m in LINK.finditer(text)}):
                if "://" in target or target.startswith("mailto:"):
                    continue
                if not (doc.parent / target).exists():
                    missing.append(f"{doc.relative_to(ROOT)}: link {target}")
    assert not missing, "\n".join(missing)
