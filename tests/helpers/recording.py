"""A recording fake of system commands (systemctl, journalctl...) put first on PATH: each call
appends its argv to a log the test reads back; ``show`` prints a canned answer."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

FAKE = """#!{python}
import json, os, sys
name = os.path.basename(sys.argv[0])
with open(os.environ["FAKE_COMMANDS_LOG"], "a") as log:
    log.write(json.dumps([name, *sys.argv[1:]]) + "\\n")
if "show" in sys.argv:
    print(os.environ.get("FAKE_COMMANDS_SHOW", ""), end="")
sys.exit(int(os.environ.get("FAKE_COMMANDS_EXIT", "0")))
"""


class RecordingFake:
    """Fakes of ``names`` in ``root/bin``; ``env()`` puts them first on PATH; ``calls()`` are
    the command lines they were given, in order."""

    def __init__(self, root: Path, names: tuple[str, ...] = ("systemctl", "journalctl")) -> None:
        self.bin = root / "bin"
        self.log = root / "calls.jsonl"
        self.bin.mkdir(parents=True)
        for name in names:
            script = self.bin / name
            script.write_text(FAKE.format(python=sys.executable))
            script.chmod(0o755)

    def env(self, **more: str) -> dict[str, str]:
        """The environment of a command whose system commands are these fakes."""
        return {
            "PATH": f"{self.bin}{os.pathsep}{os.environ['PATH']}",
            "FAKE_COMMANDS_LOG": str(self.log),
            **more,
        }

    def calls(self) -> list[list[str]]:
        """Each call's command name and arguments, oldest first."""
        if not self.log.exists():
            return []
        return [json.loads(line) for line in self.log.read_text().splitlines()]

    def forget(self) -> None:
        """Forget the calls so far."""
        self.log.unlink(missing_ok=True)
