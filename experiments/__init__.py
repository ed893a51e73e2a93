"""Many matches or measurements at once: tournaments (local pools or a Ray
cluster), facts over many matches, benchmarks, start-up throughput and the
navigation benchmark (navbench/). May import arena.match, arena.review and every
package below them; imported by scenarios (its benchmark), learn and the CLI."""
