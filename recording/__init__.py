"""MCAP recordings: the reader behind `arena review` and `arena replay`
(reader.py), the Foxglove scene built from the world stream (scene.py), and
the one analysis of the World/Referee streams (analysis/). The recorder
process writes its file with foxglove-sdk's MCAP writer. May import
`arena.runtime`, `arena.navigation` and `arena.schemas`; imported by processes and the packages above."""
