"""CLI test helpers: `poppy` run as a subprocess, and what it printed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass
from typing import Any

POPPY = [sys.executable, "-m", "poppy_cli"]


@dataclass
class Result:
    """What a `poppy` run printed and returned."""

    code: int
    stdout: str
    stderr: str

    def json(self) -> Any:
        return json.loads(self.stdout)


def run_poppy(*args: str, timeout: float = 60, input: str | None = None) -> Result:
    """Run `poppy ARGS...` and capture its output."""
    env = dict(os.environ, COLUMNS="200", NO_COLOR="1")
    proc = subprocess.run(
        [*POPPY, *args], capture_output=True, text=True, timeout=timeout, env=env, input=input
    )
    return Result(proc.returncode, proc.stdout, proc.stderr)
