"""Randomised starts: a number of a scenario's `start` or `step` given as a range, drawn per run.

`x = { uniform = [3.0, 5.0] }` draws a float, `robot = ... n = { int = [1, 3] }`
a whole number (both ends included). Each number draws from its own stream,
`runtime/seeds.py` `rng(seed, "scenario", name, key)` with the key's path in
the file (`start.ball.x`, `step[2].robots[0].y`): the same draws on every
rerun and on both engines (the engine gets the drawn numbers in the match
configuration), and adding a range elsewhere shifts no other draw. A run's
drawn values are in its verdict (`Verdict.drawn`), so a pass rate over seeds is
a pass rate over starts.

The loader validates a scenario at both ends of every range (`ends`): every
check is on a box (inside the fence, a speed at most ...), so both ends in
range put every draw in range."""

from __future__ import annotations

import math
from collections.abc import Iterator

import msgspec
from msgspec import Struct

from arena.runtime.seeds import rng

SECTIONS = ("start", "step")  # where a range may stand


class Draw(Struct, kw_only=True, forbid_unknown_fields=True):
    """`{ uniform = [a, b] }` or `{ int = [a, b] }`: one number drawn per run."""

    uniform: list[float] | None = None
    int_: list[int] | None = msgspec.field(default=None, name="int")

    def bounds(self, where: str) -> tuple[float, float]:
        if (self.uniform is None) == (self.int_ is None):
            raise ValueError(f"{where}: a range is {{ uniform = [a, b] }} or {{ int = [a, b] }}")
        key, ab = ("uniform", self.uniform) if self.uniform is not None else ("int", self.int_)
        assert ab is not None
        if len(ab) != 2 or not all(math.isfinite(v) for v in ab) or ab[0] > ab[1]:
            raise ValueError(f"{where}.{key}: [low, high] with low <= high, both finite, got {ab}")
        return ab[0], ab[1]

    def draw(self, seed: int, name: str, key: str) -> float | int:
        r = rng(seed, "scenario", name, key)
        if self.int_ is not None:
            return r.randint(self.int_[0], self.int_[1])
        assert self.uniform is not None
        return r.uniform(self.uniform[0], self.uniform[1])


def _walk(node: object, path: str) -> Iterator[tuple[str, dict, str | int]]:
    """(path, container, key) of every range-shaped table below `node`."""
    if isinstance(node, dict):
        for k, v in node.items():
            sub = f"{path}.{k}" if path else k
            if isinstance(v, dict) and set(v) and set(v) <= {"uniform", "int"}:
                yield sub, node, k
            else:
                yield from _walk(v, sub)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            if isinstance(v, dict) and set(v) and set(v) <= {"uniform", "int"}:
                yield f"{path}[{i}]", node, i  # type: ignore[misc]
            else:
                yield from _walk(v, f"{path}[{i}]")


def ranges(spec_dict: dict) -> list[tuple[str, dict, str | int]]:
    """Every range of a scenario table (as builtins), in file order, with its key's path."""
    out = []
    for section in SECTIONS:
        if section in spec_dict:
            out += list(_walk(spec_dict[section], section))
    return out


def resolve(spec, seed: int | None, end: str = "", where: str = "scenario"):
    """`spec` with every range replaced: by its draw at `seed`, or by its `end` if seed is None ("low",
    "high", or "far": the end farther from 0, so that a speed's size is checked at its largest).

    Returns (the resolved spec, {key path: value drawn}); a spec without ranges comes back as it is.
    """
    data = msgspec.to_builtins(spec)
    found = ranges(data)
    if not found:
        return spec, {}
    drawn: dict[str, float | int] = {}
    for path, holder, key in found:
        d = msgspec.convert(holder[key], Draw)  # type: ignore[index]
        lo, hi = d.bounds(f"{where}.{path}")
        if seed is None:
            value = {"low": lo, "high": hi}.get(end, lo if abs(lo) > abs(hi) else hi)
        else:
            value = d.draw(seed, spec.name, path)
            drawn[path] = round(value, 6) if isinstance(value, float) else value
        holder[key] = value  # type: ignore[index]
    return msgspec.convert(data, type(spec)), drawn
