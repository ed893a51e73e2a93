"""Looking back at a recorded match: the review (summary, pictures, GIF), the
replay to Foxglove and its HTML page, plots and the text report. May import
tools.launch and every package below tools/; only tools.experiments and the
CLI import it."""
