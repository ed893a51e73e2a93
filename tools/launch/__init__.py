"""Start, supervise and collect one match, with either engine: the launcher
(processes over zenoh), fork server and forked start, `arena run` of one
process, the witness of external digests, fault blame, compose files and the
in-process engine. May import every package below tools/; imported by
tools.experiments, tools.review and the CLI, never by them in turn."""
