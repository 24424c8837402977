"""The `poppy` command groups, one module each."""
