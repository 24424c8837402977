"""Process-wide CLI flags set by the root callback (the CLI runs one command per process)."""

debug = False
quiet = False
"""`--quiet`: only errors on stderr (see ``poppy_cli.output``)."""
