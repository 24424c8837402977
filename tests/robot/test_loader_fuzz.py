"""Config and move loaders fed random and adversarial documents: bounded memory and CPU time."""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path

import pytest

from tests.robot.loader_fuzz import (
    ALIAS_BOMB_ISSUE,
    check_config_text,
    check_move_bytes,
    config_data_property,
    config_text_property,
    move_property,
)

ROOT = Path(__file__).resolve().parents[2]
CPU_SECONDS = 240
"""CPU time (not wall-clock) the child may use for every property; a hang hits it."""
ADDRESS_SPACE = 3 << 30
"""The child's whole address space: the alias bomb alone used to take 4.6 GB."""


def test_config_texts() -> None:
    config_text_property()


def test_config_data() -> None:
    config_data_property()


def test_move_files() -> None:
    move_property()


def test_the_issue_documents() -> None:
    check_config_text(ALIAS_BOMB_ISSUE)
    check_move_bytes(
        b'{"framerate": 1e6, "positions": {"0.0": {"m1": [0, 0]}, "100000.0": {"m1": [1, 0]}}}'
    )


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_CPU, (CPU_SECONDS, CPU_SECONDS))
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))


@pytest.mark.slow
def test_every_property_under_cpu_and_memory_limits() -> None:
    code = "from tests.robot.loader_fuzz import run_all; run_all(); print('ok')"
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        capture_output=True,
        text=True,
        preexec_fn=_limits,
        timeout=CPU_SECONDS * 3,
    )
    assert done.returncode == 0, (done.returncode, done.stderr[-3000:])
    assert done.stdout.strip() == "ok"
