"""Looking back at a match: the review of a recording (summary, pictures, GIF), the
replay and its HTML page, plots, the text report of a match result, and the rich
console every printer of the commands uses (console.py). May import arena.match and
every package below it; imported by experiments, scenarios, learn and the CLI."""
