"""Marks the slow tests: ``make test-fast`` (``pytest -m "not slow"``) skips them.

A test is slow when it starts programs (``poppy`` subprocesses, tmux, a browser), runs a Textual
app, an HTTP server or MuJoCo physics, moves whole simulated creatures, or waits for things on
purpose (bus loss, soak-like runs, fuzzing). Whole
folders and modules of that kind are listed here, so that a test added to them is marked too;
a single slow test elsewhere takes ``@pytest.mark.slow``. ``make test`` runs everything.
"""

from __future__ import annotations

from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
SLOW_FOLDERS = {"cli", "creatures", "server", "sim", "teleop", "tui"}
SLOW_MODULES = {
    "emulator/test_emulator_threads.py",
    "kinematics/test_sim_chain.py",
    "robot/test_bus_loss.py",
    "robot/test_config_hypothesis.py",
}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        try:
            relative = Path(str(item.path)).resolve().relative_to(TESTS)
        except ValueError:
            continue
        if relative.parts[0] in SLOW_FOLDERS or relative.as_posix() in SLOW_MODULES:
            item.add_marker(pytest.mark.slow)
