"""`poppy record` never loses a take: bad folders refused first, full disks fall back, no twins."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_core.motion import read_move
from tests.helpers.cli import POPPY, command_env
from tests.helpers.processes import read_until, start, start_on_pty
from tests.helpers.terminal import CTRL_C, Terminal
from tests.helpers.waiting import scaled

SIM = ("--sim", "--profile", "ergo-jr")


@contextlib.contextmanager
def tmpfs(folder: Path, size: str, *options: str) -> Iterator[Path]:
    """A small tmpfs mounted on ``folder`` (root only; the test is skipped otherwise)."""
    folder.mkdir(parents=True, exist_ok=True)
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", ",".join([f"size={size}", *options]), "tmpfs", str(folder)],
        capture_output=True,
    )
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {mounted.stderr.decode().strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)


@pytest.fixture(autouse=True)
def env(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    monkeypatch.delenv("POPPY_PROFILE", raising=False)
    monkeypatch.delenv("POPPY_PORT", raising=False)
    return tmp_path


def test_a_read_only_library_is_refused_before_recording(
    poppy: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with tmpfs(tmp_path / "ro", "64k", "ro") as library:
        monkeypatch.setenv("POPPY_MOVES_DIR", str(library))
        result = poppy("record", "wave", *SIM, "--duration", "5")
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert lines == [f"error: cannot write in {library}: read-only file system"], result.stderr
    assert list((tmp_path / "tmp").iterdir()) == []


def test_a_full_disk_keeps_the_take_in_a_temporary_file(
    poppy: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with tmpfs(tmp_path / "full", "32k") as library:
        (library / "filler").write_bytes(b"\0" * 28_000)  # about 4 kB left: the take outgrows it
        monkeypatch.setenv("POPPY_MOVES_DIR", str(library))
        result = poppy("record", "wave", *SIM, "--duration", "6")
        assert sorted(p.name for p in library.iterdir()) == ["filler"]  # no lock, no half file
    assert result.code == 1
    assert result.stderr.count("checkpoint to") <= 1  # once, not every second
    assert "unexpected" not in result.stderr
    saved = Path(result.stdout.strip().splitlines()[-1])
    assert saved.parent == tmp_path / "tmp" and saved.name.startswith("poppy-take-wave-")
    assert f"the take was saved to {saved} instead" in result.stderr
    assert len(read_move(saved)) > 250  # the whole take (6 s at 50 Hz)


def test_output_saves_elsewhere(
    poppy: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "moves"))
    out = tmp_path / "takes"
    out.mkdir()
    result = poppy("record", "wave", *SIM, "--duration", "0.5", "--output", str(out))
    assert result.code == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == str(out / "wave.move")
    assert len(read_move(out / "wave.move")) > 10


def test_two_recordings_of_one_name_at_once(
    poppy: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "moves"))
    first = start([*POPPY, "record", "same", *SIM, "--duration", "20"])
    try:
        assert first.stderr is not None
        line = first.stderr.readline()
        assert line.startswith("recording "), line
        second = poppy("record", "same", *SIM, "--duration", "1", "--force")
        assert second.code == 1
        assert "another poppy process" in second.stderr and str(first.pid) in second.stderr
    finally:
        first.terminate()
        first.communicate(timeout=scaled(20))
    assert first.returncode == 0
    assert len(read_move(tmp_path / "moves" / "same.move")) > 0  # the first take, untouched


def test_on_a_terminal_another_place_is_asked_for(tmp_path: Path) -> None:
    with tmpfs(tmp_path / "full", "32k") as library:
        (library / "filler").write_bytes(b"\0" * 28_000)
        env = dict(os.environ, **command_env({"POPPY_MOVES_DIR": str(library), "COLUMNS": "200"}))
        proc, parent, child = start_on_pty([*POPPY, "record", "wave", *SIM, "--duration", "6"], env)
        os.close(child)
        try:
            shown = read_until(parent, "Save it where?")
            assert "no space left on the device" in shown
            os.write(parent, f"{tmp_path / 'missing' / 'x.move'}\n".encode())
            assert "does not exist" in read_until(parent, "Save it where?")
            os.write(parent, f"{tmp_path}\n".encode())
            tail = read_until(parent, "recorded")
            assert "recorded" in tail, tail[-2000:]
            assert proc.wait(timeout=scaled(30)) == 0
        finally:
            if proc.poll() is None:
                proc.kill()
            os.close(parent)
    assert len(read_move(tmp_path / "wave.move")) > 250


@pytest.mark.parametrize(("stop", "code"), [("ctrl-c", 130), ("sigterm", 143)])
def test_ctrl_c_where_to_save_keeps_the_take_in_a_temporary_file(
    tmp_path: Path, stop: str, code: int
) -> None:
    with tmpfs(tmp_path / "full", "32k") as library:
        (library / "filler").write_bytes(b"\0" * 28_000)
        terminal = Terminal(
            "record", "wave", *SIM, "--duration", "6", env={"POPPY_MOVES_DIR": str(library)}
        )
        try:
            assert "Save it where?" in terminal.read_until("Save it where?")
            if stop == "ctrl-c":
                terminal.type(CTRL_C)
            else:
                terminal.signal(signal.SIGTERM)
            assert terminal.wait(timeout_s=30) == code, terminal.text[-2000:]
        finally:
            terminal.close()
    [kept] = list((tmp_path / "tmp").glob("poppy-take-wave-*.move"))
    assert f"the take was saved to {kept}" in terminal.text
    assert len(read_move(kept)) > 250 and "Traceback" not in terminal.text
