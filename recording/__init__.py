"""MCAP recordings: the writer the recorder process uses (writer.py), the
reader behind `arena review` and `arena replay` (reader.py), and the Foxglove
scene built from the world stream (scene.py). May import `arena.runtime` and
`arena.schemas`; imported by processes and tools."""
