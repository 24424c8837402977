"""poppy_core.files: atomic writes that never clobber what is not theirs to replace."""

from __future__ import annotations

import errno
import os
import resource
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from poppy_core.errors import FileError
from poppy_core.files import is_disk_full, output_path, probe_folder, write_file


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


def test_new_file_gets_the_umask(tmp_path: Path) -> None:
    old = os.umask(0o027)
    try:
        path = write_file(tmp_path / "a.txt", "hello")
    finally:
        os.umask(old)
    assert path.read_text() == "hello"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640  # 0o666 & ~0o027, not mkstemp's 0o600
    assert _leftovers(tmp_path) == []


def test_existing_file_refused_without_replace_kept_mode_with(tmp_path: Path) -> None:
    path = tmp_path / "a.txt"
    path.write_text("old")
    path.chmod(0o604)
    with pytest.raises(FileError, match="already exists: pass --force"):
        write_file(path, "new")
    assert path.read_text() == "old"
    write_file(path, "new", replace=True)
    assert path.read_text() == "new"
    assert stat.S_IMODE(path.stat().st_mode) == 0o604
    assert _leftovers(tmp_path) == []


def test_a_fifo_is_never_replaced(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    for replace in (False, True):
        with pytest.raises(FileError, match="is a FIFO"):
            write_file(fifo, "data", replace=replace)
        with pytest.raises(FileError, match="is a FIFO"):
            output_path(fifo, replace=replace)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert _leftovers(tmp_path) == []


def test_a_symlink_and_its_target_are_left_alone(tmp_path: Path) -> None:
    target = tmp_path / "precious.txt"
    target.write_text("precious")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    with pytest.raises(FileError, match=f"symbolic link \\(to {target}\\)"):
        write_file(link, "overwritten", replace=True)
    assert link.is_symlink() and target.read_text() == "precious"


@pytest.mark.skipif(os.geteuid() != 0 or not Path("/dev/full").exists(), reason="needs root")
def test_a_device_node_is_never_replaced_even_as_root() -> None:
    before = os.lstat("/dev/full")
    for replace in (False, True):
        with pytest.raises(FileError, match="character device"):
            write_file("/dev/full", b"x", replace=replace)
    after = os.lstat("/dev/full")
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev


def test_a_missing_folder_is_an_error_unless_ours(tmp_path: Path) -> None:
    with pytest.raises(FileError, match="does not exist: create it first"):
        write_file(tmp_path / "no" / "a.txt", "x")
    assert not (tmp_path / "no").exists()
    written = write_file(tmp_path / "lib" / "a.txt", "x", make_folder=True)
    assert written.read_text() == "x"


def test_a_folder_takes_the_default_name(tmp_path: Path) -> None:
    assert output_path(tmp_path, default_name="wave.json") == tmp_path / "wave.json"
    with pytest.raises(FileError, match="is a folder"):
        output_path(tmp_path)
    (tmp_path / "wave.json").write_text("{}")
    with pytest.raises(FileError, match="already exists"):
        output_path(tmp_path, default_name="wave.json")


def test_a_failed_write_leaves_the_old_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "keep.txt"
    path.write_text("old")

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(FileError, match="no space left on the device") as caught:
        write_file(path, "new", replace=True)
    assert is_disk_full(caught.value)
    monkeypatch.undo()
    assert path.read_text() == "old"
    assert _leftovers(tmp_path) == []


def test_a_file_size_limit_is_a_full_disk(tmp_path: Path) -> None:
    """RLIMIT_FSIZE in a child process: the write fails with EFBIG, the old file stays."""
    code = f"""
import resource, signal
from poppy_core.errors import FileError
from poppy_core.files import is_disk_full, write_file
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
try:
    write_file({str(tmp_path / "big.bin")!r}, b"x" * 100_000, replace=True)
except FileError as exc:
    print("full" if is_disk_full(exc) else "other", exc)
"""
    (tmp_path / "big.bin").write_text("old")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("full cannot write"), out.stdout + out.stderr
    assert (tmp_path / "big.bin").read_text() == "old"
    assert _leftovers(tmp_path) == []
    assert resource and signal  # imported for the child's code


def test_probe_folder(tmp_path: Path) -> None:
    assert probe_folder(tmp_path) == tmp_path
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(FileError, match="does not exist"):
        probe_folder(tmp_path / "missing")
    (tmp_path / "file").write_text("x")
    with pytest.raises(FileError, match="not a folder"):
        probe_folder(tmp_path / "file")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in read-only folders")
def test_probe_a_read_only_folder(tmp_path: Path) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        with pytest.raises(FileError, match="permission denied"):
            probe_folder(folder)
    finally:
        folder.chmod(0o700)


def test_a_lock_file_removed_under_a_waiting_writer_does_not_let_two_in(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The known race: B opens the lock file, A releases it (and removes it), B locks the removed
    file, C makes a new one and locks it too. B must notice and lock the new file instead."""
    from poppy_core.files import FileLock

    target = tmp_path / "take.move"
    first = FileLock(target).acquire()
    real_open = os.open
    opened: list[int] = []

    def open_then_holder_releases(path: object, flags: int, mode: int = 0o777) -> int:
        fd = real_open(path, flags, mode)  # type: ignore[arg-type]
        opened.append(fd)
        if len(opened) == 1:
            first.release()  # in B's window between open() and flock()
        return fd

    monkeypatch.setattr(os, "open", open_then_holder_releases)
    second = FileLock(target).acquire()
    monkeypatch.setattr(os, "open", real_open)
    with pytest.raises(FileError, match="is writing"):
        FileLock(target).acquire()
    assert second.held
    second.release()
    third = FileLock(target).acquire()  # free again once B is done
    third.release()
    assert not (tmp_path / ".take.move.lock").exists()


def test_a_secret_is_its_owner_s_alone_from_its_creation(tmp_path: Path) -> None:
    old = os.umask(0)  # the loosest umask: the mode asked for still holds
    try:
        secret = write_file(tmp_path / "token", "s3cret\n", mode=0o600)
        assert stat.S_IMODE(secret.stat().st_mode) == 0o600
        shared = tmp_path / "shared"
        shared.write_text("old")
        shared.chmod(0o644)
        write_file(shared, "new", replace=True, mode=0o600)  # not the replaced file's bits
        assert stat.S_IMODE(shared.stat().st_mode) == 0o600 and shared.read_text() == "new"
    finally:
        os.umask(old)
