"""`poppy camera`: list, snapshot and detect on a simulated Ergo Jr; one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers.cli import run_poppy

pytest.importorskip("cv2")


def poppy(*args: str) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` in this process (as a fresh one would), for commands that do not render."""
    result = run_poppy(*args)
    return subprocess.CompletedProcess(args, result.code, result.stdout, result.stderr)


def poppy_rendering(*args: str) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` in a process of its own: OpenGL stays out of the test process."""
    return subprocess.run([sys.executable, "-m", "poppy_cli", *args], capture_output=True,
                          text=True, timeout=120, check=False)  # fmt: skip


def test_list_prints_json() -> None:
    result = poppy("camera", "list", "--json")
    assert result.returncode == 0
    assert isinstance(json.loads(result.stdout), list)


def test_a_missing_device_is_one_line() -> None:
    result = poppy("camera", "snapshot", "-o", "x.png", "--device", "/dev/video99")
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [
        "error: camera 'camera': /dev/video99 does not exist: plug the camera in "
        "(`poppy camera list` shows them)"
    ]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("snapshot", "-o", "x.gif", "--sim", "mujoco"), "use .png or .jpg"),
        (("snapshot", "-o", "no/such/dir/x.png"), "is not a folder"),
        (("detect", "--marker", "7"), "add --sim mujoco"),
        (("snapshot", "-o", "x.png", "--resolution", "big"), "WIDTHxHEIGHT"),
    ],
)
def test_usage_errors_are_one_line(args: tuple[str, ...], words: str) -> None:
    result = poppy("camera", *args)
    assert result.returncode == 2 and words in result.stderr
    assert "Traceback" not in result.stderr


def test_snapshot_and_detect_in_simulation(tmp_path: Path) -> None:
    out = tmp_path / "head.png"
    result = poppy_rendering("camera", "snapshot", "-o", str(out), "--sim", "mujoco",
                             "--profile", "ergo-jr", "--marker", "7",
                             "--resolution", "320x240")  # fmt: skip
    if result.returncode != 0 and "cannot render" in result.stderr:
        pytest.skip(f"no OpenGL here: {result.stderr.strip()}")
    assert result.returncode == 0, result.stderr
    import cv2

    image = cv2.imread(str(out))
    assert image.shape == (240, 320, 3)
    detected = poppy_rendering("camera", "detect", "--sim", "mujoco", "--profile", "ergo-jr",
                               "--card", "caribou", "--marker", "3", "--json")  # fmt: skip
    assert detected.returncode == 0, detected.stderr
    found = {(m["id"], m["card"]) for m in json.loads(detected.stdout)}
    assert found == {(3, None), (221052793, "caribou")}
