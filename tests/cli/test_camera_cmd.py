"""`poppy camera`: list, snapshot and detect on a simulated Ergo Jr; one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers.cli import run_poppy, run_poppy_process
from tests.helpers.waiting import scaled

pytest.importorskip("cv2")


def poppy(*args: str) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` in this process (as a fresh one would), for commands that do not render."""
    result = run_poppy(*args)
    return subprocess.CompletedProcess(args, result.code, result.stdout, result.stderr)


def poppy_rendering(*args: str) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` in a process of its own: OpenGL stays out of the test process."""
    return subprocess.run(
        [sys.executable, "-m", "poppy_cli", *args],
        capture_output=True,
        text=True,
        timeout=scaled(120.0),
        check=False,
    )


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
    result = poppy_rendering(
        "camera",
        "snapshot",
        "-o",
        str(out),
        "--sim",
        "mujoco",
        "--profile",
        "ergo-jr",
        "--marker",
        "7",
        "--resolution",
        "320x240",
    )
    if result.returncode != 0 and "cannot render" in result.stderr:
        pytest.skip(f"no OpenGL here: {result.stderr.strip()}")
    assert result.returncode == 0, result.stderr
    import cv2

    image = cv2.imread(str(out))
    assert image.shape == (240, 320, 3)
    detected = poppy_rendering(
        "camera",
        "detect",
        "--sim",
        "mujoco",
        "--profile",
        "ergo-jr",
        "--card",
        "caribou",
        "--marker",
        "3",
        "--json",
    )
    assert detected.returncode == 0, detected.stderr
    found = {(m["id"], m["card"]) for m in json.loads(detected.stdout)}
    assert found == {(3, None), (221052793, "caribou")}


def test_a_missing_folder_is_one_line() -> None:
    result = poppy("camera", "snapshot", "-o", "no/such/dir/x.png")
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [
        "error: cannot write in no/such/dir: the folder does not exist: create it first"
    ]


@pytest.mark.parametrize(
    ("device", "words"),
    [
        ("-5", "the device index must be 0-255, got -5"),
        ("99999999999999999999", "the device index must be 0-255, got 99999999999999999999"),
        ("256", "the device index must be 0-255, got 256"),
    ],
)
def test_device_numbers_are_checked_before_opencv_sees_them(device: str, words: str) -> None:
    result = run_poppy_process("camera", "snapshot", "-o", "x.png", f"--device={device}")
    assert result.code == 1, result.stderr  # not a crash of OpenCV (-11), not "unexpected"
    assert result.stderr.strip().splitlines() == [
        f"error: sensor 'camera': {words} (-1: the first camera found)"
    ]


def test_device_minus_one_is_the_first_camera_found_without_opencv_searching() -> None:
    if list(Path("/dev").glob("video*")):
        pytest.skip("a camera is plugged in here: -1 would open it")
    result = run_poppy_process("camera", "snapshot", "-o", "x.png", "--device=-1")
    assert result.code == 1, result.stderr  # OpenCV's own search crashed (signal 11)
    assert "no camera found" in result.stderr


SIM = ("--sim", "--profile", "ergo-jr")


def test_snapshot_writes_through_the_one_atomic_writer(tmp_path: Path) -> None:
    import os
    import stat

    target = tmp_path / "shot.png"
    old = os.umask(0o027)
    try:
        first = poppy("camera", "snapshot", "-o", str(target), *SIM)
    finally:
        os.umask(old)
    assert first.returncode == 0, first.stderr
    assert stat.S_IMODE(target.stat().st_mode) == 0o640  # the umask, not always 0600
    target.write_bytes(b"mine")
    again = poppy("camera", "snapshot", "-o", str(target), *SIM)
    assert again.returncode == 1 and "already exists: pass --force" in again.stderr
    assert target.read_bytes() == b"mine"
    forced = poppy("camera", "snapshot", "-o", str(target), *SIM, "--force")
    assert forced.returncode == 0, forced.stderr
    assert target.read_bytes().startswith(b"\x89PNG")
    into = poppy("camera", "snapshot", "-o", str(tmp_path), *SIM)  # a folder: snapshot.png in it
    assert into.returncode == 0, into.stderr
    assert (tmp_path / "snapshot.png").read_bytes().startswith(b"\x89PNG")


def test_snapshot_never_replaces_a_link_or_a_fifo(tmp_path: Path) -> None:
    import os

    kept = tmp_path / "kept.png"
    kept.write_bytes(b"kept")
    link = tmp_path / "link.png"
    link.symlink_to(kept)
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    for path in (link, fifo):
        result = poppy("camera", "snapshot", "-o", str(path), *SIM, "--force")
        assert result.returncode == 1, result.stderr
        assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
    assert link.is_symlink() and kept.read_bytes() == b"kept"
    assert fifo.is_fifo()
