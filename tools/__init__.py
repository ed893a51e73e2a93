"""What the `arena` commands do: the launcher and supervision of a match,
`arena run`/`up`, tournaments, benchmarks, review, replay and the navigation
benchmark. May import every package below it; only `arena.cli` imports it."""
