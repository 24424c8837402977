"""poppy_cli: the `poppy` command line and terminal UI."""
