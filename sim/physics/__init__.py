"""The engine's physical world: field, fence, goals, ball and robots in pymunk.

SI units throughout (m, s, kg, rad). The frame is the field frame of
schemas/messages.py: origin at the centre spot, x along the length (goal
lines at x = +-length/2), y across, theta from +x counter-clockwise. The
world is top-down 2D with no gravity; only the ball has a height z.

One `Physics` per match, assembled from one module per concern:

* `model.py`: the class, its state, `set_command` and `step` (one control
  tick of `substeps` pymunk steps);
* `world.py`: world building (fence, goals, ball, robots, drive joints) and
  the batch snapshot of every body;
* `ball.py`: ball flight (height, bounces, kicks, lobs) and placement;
* `possession.py`: the dribbler's capture, hold, challenges and losses;
* `events.py`: touches, line crossings, goals, no progress and fouls, and
  play on or off;
* `placement.py`: robot placement, parking and kick-off positions;
* `stuck.py`: robots driven but staying in one place (ROBOT_STUCK), asked by the engine;
* `state.py`: the reads (poses, `World`);
* `bodies.py`: the constants and the per-robot record.

Nothing here is random or reads a clock: equal inputs give equal outputs.
Callers import from the package: `from arena.sim.physics import Physics`.
"""

from arena.navigation.frames import wrap_angle  # the one wrap_angle, (-pi, pi]; re-exported for callers
from arena.sim.physics.bodies import (
    BOUNCE_STOP,
    CATCH_MAX_Z,
    CHALLENGE_DIST,
    DRIBBLE_HALF_WIDTH,
    DRIBBLE_REACH,
    NO_CATCH_S,
    NO_CHALLENGE_S,
    PIN_TOLERANCE,
)
from arena.sim.physics.model import Physics
from arena.sim.physics.stuck import StuckWatch

__all__ = [
    "StuckWatch",
    "BOUNCE_STOP",
    "CATCH_MAX_Z",
    "CHALLENGE_DIST",
    "DRIBBLE_HALF_WIDTH",
    "DRIBBLE_REACH",
    "NO_CATCH_S",
    "NO_CHALLENGE_S",
    "PIN_TOLERANCE",
    "Physics",
    "wrap_angle",
]
