"""One small module per `arena` sub-command: it builds its parser and calls a typed function."""
