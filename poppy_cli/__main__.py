"""Allow `python -m poppy_cli`."""

from poppy_cli.main import main

main()
