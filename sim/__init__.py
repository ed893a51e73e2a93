"""The simulated world the engine owns: pymunk physics (physics/), wheel
drive (drive.py), the robots' noisy sensors (sensors.py) and a scenario's steps
on the physics (director.py). No transport and no clock: the engine process
calls it once per tick. May import
`arena.navigation`, `arena.runtime` and `arena.schemas`; imported by
`arena.processes` and the packages above it."""
