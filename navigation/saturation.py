"""Wheel-speed saturation that keeps the direction of motion.

Not from the papers: a wheel command vector w (any drive: paper 1 eq. 2,
paper 2 eq. 3-4, paper 3 eq. 13) whose largest magnitude exceeds the motor
limit w_max is scaled as a whole,

    w' = w * min(1, w_max / max_i |w_i|),

instead of clipping each wheel. Kinematics are linear, so the body twist is
scaled by the same factor: the robot keeps its direction of travel and its
ratio of translation to rotation (for a differential drive, its path
curvature), and only slows down.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray


def saturation_scale(wheels: Sequence[float] | NDArray[np.float64], max_wheel_speed: float) -> float:
    """The factor s in (0, 1] that brings max |w_i| down to ``max_wheel_speed`` (same unit as ``wheels``)."""
    if max_wheel_speed <= 0.0:
        raise ValueError(f"max_wheel_speed must be positive, got {max_wheel_speed}")
    peak = max((abs(float(w)) for w in wheels), default=0.0)
    return 1.0 if peak <= max_wheel_speed else max_wheel_speed / peak


def saturate(wheels: Sequence[float] | NDArray[np.float64], max_wheel_speed: float) -> NDArray[np.float64]:
    """``wheels`` scaled together so that no wheel exceeds ``max_wheel_speed``; a new float array."""
    w = np.asarray(wheels, dtype=np.float64)
    return w * saturation_scale(w, max_wheel_speed)
