"""Process-wide CLI flags set by the root callback (the CLI runs one command per process)."""

debug = False
