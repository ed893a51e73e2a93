"""What the `arena` commands do, in three sub-packages by concern:
`launch` (start, supervise and collect one match, either engine),
`experiments` (many matches: tournaments, clusters, facts, benchmarks) and
`review` (looking back at a recorded match). May import every package below
it; only the packages above it (scenarios, learn, the CLI) import it."""
