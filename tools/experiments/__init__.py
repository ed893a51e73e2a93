"""Many matches or measurements at once: tournaments (local pools or a Ray
cluster), facts over many matches, benchmarks, start-up throughput and the
navigation benchmark (navbench/). May import tools.launch and tools.review and
every package below tools/; only the CLI imports it."""
