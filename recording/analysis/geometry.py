"""Geometry the match facts need: robot footprints and a rolling ball's crossing of a line."""

from __future__ import annotations

import math


def footprint_overlap(a, b, half: float) -> float:
    """Overlap [m] of two squares of half side `half` (a, b: x, y, theta); negative: the gap.

    Separating-axis test over the four face normals; the result is the smallest
    penetration along them (the gap along the best separating axis when apart).
    """
    dx, dy = b[0] - a[0], b[1] - a[1]
    best = math.inf
    ca, sa, cb, sb = math.cos(a[2]), math.sin(a[2]), math.cos(b[2]), math.sin(b[2])
    for ux, uy in ((ca, sa), (-sa, ca), (cb, sb), (-sb, cb)):
        # projection radius of each square on the axis
        ra = half * (abs(ux * ca + uy * sa) + abs(-ux * sa + uy * ca))
        rb = half * (abs(ux * cb + uy * sb) + abs(-ux * sb + uy * cb))
        best = min(best, ra + rb - abs(dx * ux + dy * uy))
    return best


def crossing_y(x: float, y: float, vx: float, vy: float, line_x: float) -> float | None:
    """y [m] at which a ball at (x, y) moving with (vx, vy) crosses x = line_x; None if it moves away."""
    if vx == 0.0 or (line_x - x) * vx <= 0.0:
        return None
    return y + vy * (line_x - x) / vx
