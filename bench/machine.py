"""Describe the machine a benchmark ran on: CPU model, cores, OS, Python versions, date."""

from __future__ import annotations

import datetime as dt
import os
import platform
import subprocess
from pathlib import Path
from typing import Any


def cpu_model() -> str:
    """The CPU model name (from /proc/cpuinfo on Linux, ``platform.processor()`` elsewhere)."""
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        for line in cpuinfo.read_text(errors="replace").splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or platform.machine() or "unknown"


def python_version(python: Path | str) -> str:
    """The version of another interpreter (``unknown`` if it cannot run)."""
    try:
        done = subprocess.run(
            [str(python), "-c", "import platform; print(platform.python_version())"],
            capture_output=True,
            text=True,
            timeout=30,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return done.stdout.strip() or "unknown"


def machine_info(peers_python: Path | None = None) -> dict[str, Any]:
    """Everything docs/performance.md says about where and when the run happened.

    Args:
        peers_python: the peers venv's interpreter, whose version is reported too.

    Returns:
        A JSON-ready dict: cpu, cores, os, python, peers_python, date (UTC, ISO 8601).
    """
    return {
        "cpu": cpu_model(),
        "cores": os.cpu_count() or 0,
        "os": platform.platform(),
        "python": platform.python_version(),
        "peers_python": python_version(peers_python) if peers_python is not None else None,
        "date": dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat(),
    }
