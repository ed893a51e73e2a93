"""Reading a file a user hands over (a configuration, a settings file): bounded, regular, UTF-8.

`read_text` refuses, with one line naming the flag and the file, what would hang or exhaust a
reader: a FIFO or a device (`/dev/zero` never ends, a FIFO blocks until a writer comes), a
directory, a file larger than the limit, and bytes that are not UTF-8 (a recording named
by mistake). `check_depth` bounds how deep a parsed document nests, without recursion.
"""

from __future__ import annotations

import os
import stat
from itertools import accumulate

from arena.config import ConfigError

MAX_BYTES = 1 << 20  # [bytes] a configuration file is a few kB
MAX_DEPTH = 16  # [levels] tables and arrays inside one another (a match configuration uses 3)


def read_text(path: str, what: str, limit: int = MAX_BYTES) -> str:
    """The text of the regular file `path`; ConfigError (one line, starting with `what`) otherwise."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise ConfigError(f"cannot read {what} {path}: {exc.strerror}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a directory" if stat.S_ISDIR(st.st_mode) else "not a regular file"
            raise ConfigError(f"{what} {path} is {kind}: give a file")
        if st.st_size > limit:
            raise ConfigError(f"{what} {path} is {st.st_size} bytes, more than {limit} (is it the right file?)")
        chunks, size = [], 0
        while size <= limit:  # a file growing while it is read is still bounded
            chunk = os.read(fd, 65536)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            raise ConfigError(f"{what} {path} is more than {limit} bytes (is it the right file?)")
    except OSError as exc:
        raise ConfigError(f"cannot read {what} {path}: {exc.strerror}") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"{what} {path} is not a text file (byte {exc.start} is not UTF-8; a recording or a binary?)"
        ) from None


def check_depth(doc: object, what: str, limit: int = MAX_DEPTH) -> None:
    """ConfigError when dicts and lists in `doc` nest deeper than `limit` (walked without recursion)."""
    stack = [(doc, 0)]
    while stack:
        node, depth = stack.pop()
        children = node.values() if isinstance(node, dict) else node if isinstance(node, list) else ()
        if children and depth >= limit:
            raise ConfigError(f"{what} nests tables and arrays more than {limit} levels deep")
        stack.extend((c, depth + 1) for c in children)


def load_toml(path: str, what: str, limit: int = MAX_BYTES) -> dict:
    """`read_text`, parsed as TOML and depth-checked; ConfigError (one line) for any fault."""
    import tomllib

    text = read_text(path, what, limit)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{what} {path} is not valid TOML: {exc}") from None
    except RecursionError:  # the parser recurses once per level of nested arrays and inline tables
        raise ConfigError(f"{what} {path} nests arrays or tables too deep to read") from None
    check_depth(doc, f"{what} {path}")
    return doc


# Bytes that are not brackets: deleted before counting. UTF-8 never puts an ASCII byte inside a
# multi-byte character, so counting on the encoded bytes counts exactly the brackets of the text.
_NOT_BRACKETS = bytes(b for b in range(256) if b not in b"[]{}")
_STEP = {ord("["): 1, ord("{"): 1, ord("]"): -1, ord("}"): -1}


def json_nesting(raw: str) -> int:
    """How deep arrays and objects nest in `raw` (JSON text), brackets inside strings not counted.

    Linear in the length of `raw` whatever it holds, and no regular expression: every step is one
    pass of a C string method (`replace`, `split`, `translate`) and one pass over the brackets
    left. (A backtracking pattern for JSON strings took quadratic time on an unterminated string
    of escaped quotes: 100 kB held the bridge's thread, and the GIL, for over a minute.)
    Inside strings, a run of backslashes escapes in pairs from its left, so deleting every `\\\\`
    and then every `\\"` leaves exactly the quotes that open and close strings; every other piece
    between two of them is a string. Outside strings a backslash is not JSON at all, and the
    parser stops there, before any bracket this count might then misplace.
    """
    text = raw.replace("\\\\", "").replace('\\"', "")
    outside = "".join(text.split('"')[::2])
    brackets = outside.encode("utf-8", errors="surrogatepass").translate(None, _NOT_BRACKETS)
    return max(accumulate(map(_STEP.__getitem__, brackets), initial=0))
