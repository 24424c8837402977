"""MediaPipe Pose's venv for the tests: CI makes it (.ci/run); elsewhere its absence skips."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from poppy_core.sensors.pose import pose_python


def mediapipe_python() -> Path:
    """The pose venv's interpreter; CI makes it (.ci/run), elsewhere its absence skips."""
    python = pose_python()
    if python is None:
        why = "no MediaPipe Pose venv: python -m poppy_core.sensors.pose_venv"
        if os.environ.get("CI"):
            pytest.fail(why)
        pytest.skip(why)
    return python


def fake_pose_python(folder: Path) -> Path:
    """An 'interpreter' for a PoseSkeleton's ``python`` that runs ``fake_pose_worker.py``
    (whatever worker it is asked to run): the same person in every frame, no MediaPipe."""
    fake = Path(__file__).with_name("fake_pose_worker.py")
    script = folder / "fake-python"
    script.write_text(f'#!/bin/sh\nexec "{sys.executable}" "{fake}"\n')
    script.chmod(0o755)
    return script
