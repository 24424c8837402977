"""A downloaded Snap! archive (zip or tar) unpacked: regular files and folders inside its own
folder only, within what a release holds (entries and bytes counted as they come)."""

from __future__ import annotations

import stat
import tarfile
import zipfile
import zlib
from pathlib import Path, PurePosixPath
from typing import IO

from poppy_core.errors import DownloadError

MAX_UNPACKED_BYTES = 1024 * 1024 * 1024
MAX_FILES = 50_000
"""Entries (files and folders) at most: Snap! 11.0.8 holds 1794 files (docs/snap.md)."""
CHUNK = 1 << 16


def _member_path(name: str) -> PurePosixPath | None:
    """A member's path inside the archive, or None for one that would land outside it."""
    path = PurePosixPath(name.replace("\\", "/"))
    if path.is_absolute() or ".." in path.parts or not path.parts:
        return None
    return path


def unpack(archive: Path, into: Path) -> None:
    """Unpack a zip or tar archive of regular files and folders; refuse anything else.

    Every entry counts (a folder too: 60,000 empty ones are no release), before it is made; the
    bytes are counted as they are written, whatever size the archive claims."""
    budget = _Budget()

    def bad(name: str) -> DownloadError:
        return DownloadError(f"the archive holds {name[:80]!r}, outside its folder: refused")

    if zipfile.is_zipfile(archive):
        try:
            with zipfile.ZipFile(archive) as zipped:
                for info in zipped.infolist():
                    path = _member_path(info.filename)
                    if path is None:
                        raise bad(info.filename)
                    if stat.S_ISLNK(info.external_attr >> 16):
                        raise DownloadError(
                            f"the archive holds a link {info.filename[:80]!r}: refused"
                        )
                    budget.entry(0 if info.is_dir() else info.file_size)
                    if info.is_dir():
                        (into / path).mkdir(parents=True, exist_ok=True)
                        continue
                    (into / path).parent.mkdir(parents=True, exist_ok=True)
                    with zipped.open(info) as src, (into / path).open("wb") as dst:
                        budget.copy(src, dst)
        except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError) as exc:
            raise DownloadError(f"the zip archive is damaged ({exc}): refused") from None
        return
    try:
        with tarfile.open(archive) as tarred:
            for member in tarred:
                path = _member_path(member.name)
                if path is None:
                    raise bad(member.name)
                if member.isdir():
                    budget.entry(0)
                    (into / path).mkdir(parents=True, exist_ok=True)
                elif member.isfile():
                    budget.entry(member.size)
                    (into / path).parent.mkdir(parents=True, exist_ok=True)
                    member_file = tarred.extractfile(member)
                    assert member_file is not None
                    with member_file, (into / path).open("wb") as dst:
                        budget.copy(member_file, dst)
                elif member.type not in (tarfile.XGLTYPE, tarfile.XHDTYPE):
                    raise DownloadError(f"the archive holds a link {member.name[:80]!r}: refused")
    except (tarfile.TarError, zlib.error, EOFError) as exc:
        raise DownloadError(f"the download is not a zip or tar archive ({exc})") from None


class _Budget:
    """What an archive may unpack to: ``MAX_FILES`` entries, ``MAX_UNPACKED_BYTES`` written."""

    def __init__(self) -> None:
        self.entries = 0
        self.written = 0

    def _refuse(self) -> DownloadError:
        return DownloadError("the archive unpacks to more than a Snap! release: refused")

    def entry(self, claimed: int) -> None:
        """One more entry (file or folder) claiming ``claimed`` bytes."""
        self.entries += 1
        if self.entries > MAX_FILES or self.written + claimed > MAX_UNPACKED_BYTES:
            raise self._refuse()

    def copy(self, src: IO[bytes], dst: IO[bytes]) -> None:
        """Copy ``src`` into ``dst``, counting the bytes actually read."""
        while chunk := src.read(CHUNK):
            self.written += len(chunk)
            if self.written > MAX_UNPACKED_BYTES:
                raise self._refuse()
            dst.write(chunk)
