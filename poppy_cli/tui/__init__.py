"""`poppy tui`: the Textual successor of herborist (ports, scan, motor panel, robot tab)."""
