"""Files poppy writes: atomically, only over regular files, with the user's umask; one place.

Every file poppy saves (configs, moves, plots, renders, recordings) goes through
``write_file``:

- the data goes to a temporary file beside the target, is flushed to disk, then renamed over it,
  so a reader (or a crash) sees the old file or the new one, never half of one;
- an existing target is replaced only with ``replace=True`` (the CLI's ``--force``); without it
  the new file is linked into place, which fails if anything appeared there meanwhile;
- anything that is not a regular file is never replaced: a folder, a FIFO, a device node
  (``/dev/full``), a socket, or a symbolic link (its target is named instead);
- a missing folder is an error unless the caller owns it (``make_folder=True``, the library);
- a new file gets the user's umask (created ``0o666 & ~umask`` by the kernel), a replaced one
  keeps its permission bits.

``output_path`` runs the same checks before long work (a render, a scan) so that it is refused
up front, and turns a folder into the file to write in it. Errors are ``FileError`` with one line
saying what to do.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import stat
from pathlib import Path

from poppy_core.errors import FileError

NEW_FILE_MODE = 0o666
"""Mode asked for new files; the kernel takes the umask off it."""

_KINDS = {
    stat.S_IFDIR: "a folder",
    stat.S_IFIFO: "a FIFO (named pipe)",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
    stat.S_IFLNK: "a symbolic link",
}
_REASONS = {
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "file too large (the file-size limit was reached)",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EROFS: "read-only file system",
    errno.ENOENT: "no such file or folder",
    errno.ENOTDIR: "a part of the path is not a folder",
    errno.ENAMETOOLONG: "file name too long",
    errno.EISDIR: "is a folder",
}


def file_error(exc: OSError, path: Path | str, action: str) -> FileError:
    """A one-line ``FileError`` for an ``OSError`` met while doing ``action`` on ``path``.

    Args:
        exc: the error.
        path: the file (or folder) concerned.
        action: what was tried, e.g. ``"write"``.
    """
    reason = _REASONS.get(exc.errno or 0) or exc.strerror or str(exc)
    return FileError(f"cannot {action} {path}: {reason}", path=str(path), errno=exc.errno)


def is_disk_full(error: BaseException) -> bool:
    """True for an error that says the disk (or quota, or file-size limit) is full."""
    return isinstance(error, FileError | OSError) and error.errno in (
        errno.ENOSPC,
        errno.EDQUOT,
        errno.EFBIG,
    )


def _kind(mode: int) -> str:
    return _KINDS.get(stat.S_IFMT(mode), "not a regular file")


def _check_target(path: Path, replace: bool) -> os.stat_result | None:
    """The target's stat when it is a regular file that may be replaced; None when absent.

    Raises:
        FileError: the target exists and ``replace`` is False, or it is not a regular file.
    """
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise file_error(exc, path, "write") from None
    if stat.S_ISLNK(info.st_mode):
        target = os.readlink(path)
        raise FileError(
            f"{path} is a symbolic link (to {target}): poppy does not write through links; "
            "give the real path",
            path=str(path),
        )
    if not stat.S_ISREG(info.st_mode):
        raise FileError(
            f"{path} is {_kind(info.st_mode)}, not a regular file: it is never replaced; "
            "give a file name",
            path=str(path),
        )
    if not replace:
        raise FileError(
            f"{path} already exists: pass --force to replace it", path=str(path), errno=errno.EEXIST
        )
    return info


def _check_folder(folder: Path, make_folder: bool) -> None:
    if make_folder:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise file_error(exc, folder, "create the folder") from None
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist: create it first"
        raise FileError(
            f"cannot write in {folder}: the folder {what}",
            path=str(folder),
            errno=errno.ENOTDIR if folder.exists() else errno.ENOENT,
        )


def output_path(
    path: str | os.PathLike[str],
    *,
    default_name: str | None = None,
    replace: bool = False,
    make_folder: bool = False,
) -> Path:
    """The file to write for ``path``, checked before any work is done.

    Args:
        path: a file, or a folder to write ``default_name`` into.
        default_name: the file name used when ``path`` is a folder (None: a folder is refused).
        replace: an existing regular file may be replaced.
        make_folder: create a missing parent folder (only for folders poppy owns).

    Returns:
        The file that ``write_file`` will write.

    Raises:
        FileError: see ``write_file``.
    """
    target = Path(path).expanduser()
    if target.is_dir() and not target.is_symlink():
        if default_name is None:
            raise FileError(f"{target} is a folder: give a file name", path=str(target))
        target = target / default_name
    _check_folder(target.parent if str(target.parent) else Path("."), make_folder)
    _check_target(target, replace)
    return target


def probe_folder(folder: str | os.PathLike[str], *, make_folder: bool = False) -> Path:
    """Check that files can be created in ``folder`` (a tiny file is written and removed).

    Raises:
        FileError: the folder is missing, not a folder, read-only, full or not ours.
    """
    where = Path(folder).expanduser()
    _check_folder(where, make_folder)
    probe = where / f".poppy-probe-{secrets.token_hex(6)}"
    try:
        fd = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, NEW_FILE_MODE)
        try:
            os.write(fd, b"\0")
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as exc:
        raise file_error(exc, where, "write in") from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(probe)
    return where


def write_file(
    path: str | os.PathLike[str],
    data: bytes | str,
    *,
    replace: bool = False,
    make_folder: bool = False,
    mode: int | None = None,
) -> Path:
    """Write ``data`` to ``path`` atomically (see the module docstring for the rules).

    Args:
        path: the file to write.
        data: its whole content (text is written as UTF-8).
        replace: replace an existing regular file (else it is refused).
        make_folder: create missing parent folders (only for folders poppy owns).
        mode: the file's permission bits from its creation on, whatever the umask and the
            replaced file's (``0o600`` for a secret only its owner reads).

    Returns:
        The path written.

    Raises:
        FileError: the target exists (without ``replace``) or is not a regular file, the folder
            is missing, or the write failed (``errno`` tells why: ``ENOSPC`` for a full disk...);
            the target is then untouched.
    """
    target = Path(path).expanduser()
    folder = target.parent if str(target.parent) else Path(".")
    _check_folder(folder, make_folder)
    existing = _check_target(target, replace)
    payload = data.encode("utf-8") if isinstance(data, str) else data
    temp = folder / f".{target.name[:200]}.{secrets.token_hex(6)}.tmp"
    try:
        fd = os.open(
            temp,
            os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW,
            NEW_FILE_MODE if mode is None else mode,
        )
    except OSError as exc:
        raise file_error(exc, target, "write") from None
    try:
        try:
            if mode is not None:
                os.fchmod(fd, mode)  # before any byte is written
            view = memoryview(payload)
            while view:
                view = view[os.write(fd, view) :]
            if existing is not None and mode is None:
                os.fchmod(fd, stat.S_IMODE(existing.st_mode))
            os.fsync(fd)
        finally:
            os.close(fd)
        _put_in_place(temp, target, replace)
    except OSError as exc:
        raise file_error(exc, target, "write") from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(temp)
    _sync_folder(folder)
    return target


def place_file(temp: Path, target: Path, *, replace: bool) -> None:
    """Put a finished temporary file (written beside ``target``, by a writer of its own: a
    recording streamed to disk) where it goes, as ``write_file`` does: synced first, never over
    a file without ``replace``, then the folder synced.

    Raises:
        FileError: ``target`` exists and ``replace`` is False.
        OSError: the file system refused (the caller names the file: ``file_error``).
    """
    with open(temp, "rb") as stream:
        os.fsync(stream.fileno())
    _put_in_place(temp, target, replace)
    _sync_folder(target.parent)


def _put_in_place(temp: Path, target: Path, replace: bool) -> None:
    if replace:
        # Checked again here: a FIFO or link that appeared since is refused, not replaced.
        _check_target(target, replace=True)
        os.replace(temp, target)
        return
    try:
        os.link(temp, target)  # fails if anything is there now: nothing is ever clobbered
    except FileExistsError:
        raise FileError(
            f"{target} already exists: pass --force to replace it",
            path=str(target),
            errno=errno.EEXIST,
        ) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
        _check_target(target, replace=False)  # a file system without hard links (FAT...)
        os.rename(temp, target)


def _sync_folder(folder: Path) -> None:
    """Make the rename itself durable (POSIX)."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


_LOCK_ATTEMPTS = 100
"""How often ``FileLock.acquire`` starts again on a lock file replaced under it."""


def _same_file(fd: int, path: Path) -> bool:
    """True when the open file ``fd`` is the file at ``path`` (not a removed or replaced one)."""
    try:
        at_path = os.stat(path, follow_symlinks=False)
    except OSError:
        return False
    held = os.fstat(fd)
    return (held.st_dev, held.st_ino) == (at_path.st_dev, at_path.st_ino)


class FileLock:
    """An exclusive lock on a file about to be written, held in ``.<name>.lock`` beside it.

    Two processes recording into one file would each replace the other's work: the second one
    is refused instead. The lock is advisory (``flock``) and dies with its process, so a crash
    leaves nothing stuck.

    Args:
        path: the file the lock protects.
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        target = Path(path)
        self.target = target
        self.path = target.with_name(f".{target.name[:200]}.lock")
        self._fd: int | None = None

    def acquire(self) -> FileLock:
        """Take the lock (without waiting).

        The lock file is removed by its last holder (``release``), so the file a process opened
        may be gone by the time it gets the lock, and a third process may have made and locked a
        new one: the lock counts only when the file locked is still the one at ``path`` (the
        same inode), else it is taken again on the new file. (Locking a removed file and keeping
        it let two writers hold the lock at once.)

        Raises:
            FileError: another process holds it (its pid is named), or it cannot be created.
        """
        import fcntl

        for _ in range(_LOCK_ATTEMPTS):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, NEW_FILE_MODE)
            except OSError as exc:
                raise file_error(exc, self.path, "create the lock") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 32).decode(errors="replace").strip() or "?"
                os.close(fd)
                raise FileError(
                    f"another poppy process (pid {holder}) is writing {self.target}: wait for "
                    "it, or pick another name",
                    path=str(self.target),
                    errno=errno.EBUSY,
                ) from None
            if _same_file(fd, self.path):
                os.ftruncate(fd, 0)
                os.write(fd, f"{os.getpid()}\n".encode())
                self._fd = fd
                return self
            os.close(fd)  # its holder removed it meanwhile: lock the file now at the path
        raise FileError(
            f"cannot lock {self.target}: its lock file {self.path} keeps being replaced",
            path=str(self.target),
            errno=errno.EBUSY,
        )

    def release(self) -> None:
        """Drop the lock and its file (again: nothing).

        The file is removed while still locked: a process that opened it meanwhile finds, once
        it gets the lock, that it is no longer the file at the path, and starts again.
        """
        fd, self._fd = self._fd, None
        if fd is None:
            return
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        os.close(fd)

    @property
    def held(self) -> bool:
        """True between ``acquire`` and ``release``."""
        return self._fd is not None
