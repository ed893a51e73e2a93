"""Local navigation for soccer robots: potential fields, social forces, heading
control and wheel kinematics. Pure functions over floats and numpy arrays;
no transport, no clock, no module state.

Navigators, by name (:data:`NAVIGATORS`), all with one signature::

    step(pos, vel, goal, obstacles, params=<paper defaults>) -> (vx, vy)

    pos, vel, goal  2-sequences in the field frame: position [m], current
                    velocity [m/s], goal position [m]
    obstacles       sequence of (x, y) obstacle centres [m] in the field frame
                    (list of pairs or an (M, 2) array; M may be 0)
    params          the navigator's frozen params dataclass (:data:`PARAMS`)
    returns         desired velocity (vx, vy) [m/s] in the field frame, two
                    floats, with hypot(vx, vy) <= params.max_speed

=======  ====================  ==========================================
name     module                paper
=======  ====================  ==========================================
apf      :mod:`.apf`           paper 3 eq. 2-3 (Khatib)
mapf     :mod:`.mapf`          paper 3 eq. 4-7
sfm      :mod:`.sfm`           paper 1 eq. 3-7, 17-20
f-sfm    :mod:`.fsfm`          paper 1 eq. 8-14, Fig. 4, Table 3
=======  ====================  ==========================================

The contract is spelled out in :mod:`.base`. Heading and wheels:
:mod:`.pid` (paper 1 eq. 15-16), :mod:`.omni3` (paper 1 eq. 1-2),
:mod:`.omni4` (paper 2 eq. 3-4), :mod:`.diffdrive` (paper 3 eq. 8, 9, 11, 13),
:mod:`.saturation` (direction-keeping wheel-speed limit), :mod:`.frames`.
See docs/navigation.md. Imports nothing of arena but itself; used by `arena.sim`,
`arena.strategies` and `arena.experiments` (navbench).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from arena.navigation import apf, fsfm, mapf, sfm
from arena.navigation.base import Navigator

NAVIGATORS: Mapping[str, Navigator] = MappingProxyType(
    {
        "apf": apf.step,
        "mapf": mapf.step,
        "sfm": sfm.step,
        "f-sfm": fsfm.step,
    }
)

# Name -> the params dataclass its step takes; ``PARAMS[name]()`` is the paper default.
PARAMS: Mapping[str, type] = MappingProxyType(
    {
        "apf": apf.APFParams,
        "mapf": mapf.MAPFParams,
        "sfm": sfm.SFMParams,
        "f-sfm": fsfm.FSFMParams,
    }
)


def get(name: str) -> Navigator:
    """The navigator registered as ``name``; ValueError naming the known ones otherwise."""
    try:
        return NAVIGATORS[name]
    except KeyError:
        raise ValueError(f"unknown navigator {name!r}; known: {', '.join(NAVIGATORS)}") from None


__all__ = ["NAVIGATORS", "PARAMS", "Navigator", "get"]
