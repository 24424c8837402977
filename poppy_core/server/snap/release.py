"""Snap! offline: a pinned Snap! release downloaded once, checked, unpacked atomically, found again.

The pin is a digest of the release's files, not of the archive: GitHub builds its source archives
on request, so their bytes may change while the files they hold do not. ``release_digest`` is the
SHA-256 of the sorted lines ``<git blob id>  <path>``, one per file (the blob id is git's, which
``git ls-tree -r TAG`` lists for a clone of github.com/jmoenig/Snap: docs/snap.md shows how the
pin was taken and how to take another). The archive's own SHA-256 is reported besides.
"""

from __future__ import annotations

import contextlib
import hashlib
import http.client
import json
import logging
import os
import re
import secrets
import shutil
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import platformdirs

from poppy_core.errors import ArgumentError, DownloadError, FileError
from poppy_core.server.snap.unpack import unpack

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SnapRelease:
    """A Snap! release poppy knows: its version, where GitHub serves it, its files' digest."""

    version: str
    url: str
    digest: str


PINNED = SnapRelease(
    version="11.0.8",
    url="https://github.com/jmoenig/Snap/archive/refs/tags/v11.0.8.zip",
    # release_digest of tag v11.0.8 (commit e6d096c2e4d8, tree 3d6cff6a28a0): 1794 files,
    # taken from `git ls-tree -r -z v11.0.8` of a clone (docs/snap.md)
    digest="34482f770c5d9c181586489110a614a4b2903e30ee88dbfe8e3c13486b8b710f",
)
RELEASES = {PINNED.version: PINNED}
"""The releases ``poppy snap download --version V`` fetches without ``--from``/``--sha256``."""

MARKER = ".poppy-snap.json"
"""Written in an installed copy: its version, digest and source."""
MAX_ARCHIVE_BYTES = 512 * 1024 * 1024
VERSION = re.compile(r"[0-9A-Za-z][0-9A-Za-z._-]{0,39}")
DIGEST = re.compile(r"[0-9a-f]{64}")
CHUNK = 1 << 16


@dataclass(frozen=True)
class InstalledSnap:
    """A Snap! copy in the user data folder (``path`` holds ``snap.html``)."""

    version: str
    path: Path
    digest: str
    source: str
    archive_sha256: str = ""
    downloaded: bool = False


def releases_folder() -> Path:
    """Where downloaded releases live: ``<user data>/poppy/snap/<version>/``."""
    return Path(platformdirs.user_data_dir("poppy")) / "snap"


def blob_id(data: bytes) -> str:
    """git's id of a file's content (SHA-1 of ``blob <size>\\0<content>``)."""
    return hashlib.sha1(b"blob %d\0" % len(data) + data, usedforsecurity=False).hexdigest()


def release_digest(root: Path, *, skip: tuple[str, ...] = (MARKER,)) -> str:
    """The digest of the files under ``root`` (see the module docstring)."""
    rows: list[tuple[bytes, str]] = []
    for path in root.rglob("*"):
        if path.is_symlink() or not path.is_file():
            continue
        relative = path.relative_to(root).as_posix()
        if relative in skip:
            continue
        rows.append((relative.encode("utf-8"), blob_id(path.read_bytes())))
    rows.sort()
    text = b"".join(oid.encode() + b"  " + name + b"\n" for name, oid in rows)
    return hashlib.sha256(text).hexdigest()


def _read_marker(folder: Path) -> dict[str, str]:
    try:
        data = json.loads((folder / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return {str(k): str(v) for k, v in data.items()} if isinstance(data, dict) else {}


def installed_copies() -> list[InstalledSnap]:
    """Every installed copy, the most recently installed first."""
    folder = releases_folder()
    if not folder.is_dir():
        return []
    found = []
    for child in folder.iterdir():
        if child.name.startswith(".") or not (child / "snap.html").is_file():
            continue
        marker = _read_marker(child)
        stamp = (child / MARKER).stat().st_mtime if (child / MARKER).exists() else 0.0
        copy = InstalledSnap(child.name, child, marker.get("digest", ""), marker.get("source", ""))
        found.append((stamp, copy))
    return [copy for _, copy in sorted(found, key=lambda pair: pair[0], reverse=True)]


def installed(version: str | None = None) -> InstalledSnap | None:
    """The copy of ``version``, else (no version) the most recently installed one, or None."""
    copies = installed_copies()
    if version is None:
        return copies[0] if copies else None
    return next((c for c in copies if c.version == version), None)


def _check_version(version: str) -> str:
    if not VERSION.fullmatch(version):
        raise ArgumentError(
            f"--version {version[:60]!r} is not a Snap! version: give one such as {PINNED.version}",
            field="version",
            value=version,
        )
    return version


def _check_digest(digest: str) -> str:
    value = digest.strip().lower()
    if not DIGEST.fullmatch(value):
        raise ArgumentError(
            f"--sha256 {digest[:80]!r} is not a SHA-256: give 64 hexadecimal digits "
            "(the release digest, docs/snap.md says how to take it)",
            field="sha256",
            value=digest,
        )
    return value


def plan(
    version: str | None = None, source: str | None = None, digest: str | None = None
) -> SnapRelease:
    """The release to fetch: the pinned one unless told; refuses what cannot be checked."""
    name = _check_version(version or PINNED.version)
    known = RELEASES.get(name)
    if digest is not None:
        digest = _check_digest(digest)
    elif known is not None:
        digest = known.digest
    else:
        pinned = ", ".join(sorted(RELEASES))
        raise ArgumentError(
            f"no pinned digest for Snap! {name} (poppy pins {pinned}): pass --sha256 with its "
            "release digest (docs/snap.md says how to take it)",
            field="version",
            value=name,
        )
    if source is None:
        if known is None:
            raise ArgumentError(
                f"poppy does not know where Snap! {name} is: pass --from URL", field="from"
            )
        source = known.url
    return SnapRelease(name, source, digest)


@contextlib.contextmanager
def _opened(source: str, timeout_s: float) -> Iterator[IO[bytes]]:
    """The archive's bytes: an http(s) URL, a file:// URL or a local path."""
    scheme = source.partition(":")[0].lower() if "://" in source else ""
    if scheme in ("http", "https"):
        request = urllib.request.Request(source, headers={"User-Agent": "poppy"})
        try:
            with urllib.request.urlopen(request, timeout=timeout_s) as answer:
                yield answer
        except urllib.error.HTTPError as exc:
            raise DownloadError(f"{source} answered {exc.code} {exc.reason}") from None
        except (urllib.error.URLError, TimeoutError, OSError) as exc:
            reason = getattr(exc, "reason", exc)
            raise DownloadError(
                f"cannot download {source} ({reason}): is the network up? "
                "(--from takes a mirror's URL or a file already downloaded)"
            ) from None
        return
    if scheme not in ("", "file"):
        raise ArgumentError(
            f"--from {source[:80]!r}: give an http(s) URL, a file:// URL or a file", field="from"
        )
    path = Path(urllib.request.url2pathname(source[len("file://") :]) if scheme else source)
    try:
        with path.expanduser().open("rb") as file:
            yield file
    except OSError as exc:
        raise DownloadError(f"cannot read {path}: {exc.strerror or exc}") from None


def _fetch(source: str, target: Path, timeout_s: float, progress: Callable[[int], None]) -> str:
    """Copy ``source`` into ``target``; its SHA-256."""
    sha = hashlib.sha256()
    size = 0
    with _opened(source, timeout_s) as stream, target.open("wb") as out:
        headers = getattr(stream, "headers", None)
        announced = headers.get("Content-Length") if headers is not None else None
        while True:
            try:
                chunk = stream.read(CHUNK)
            except (OSError, ValueError, http.client.HTTPException) as exc:
                raise DownloadError(f"the download of {source} broke off ({exc})") from None
            if not chunk:
                break
            size += len(chunk)
            if size > MAX_ARCHIVE_BYTES:
                raise DownloadError(
                    f"{source} is larger than {MAX_ARCHIVE_BYTES >> 20} MiB: not a Snap! release"
                )
            sha.update(chunk)
            out.write(chunk)
            progress(size)
    if announced is not None and announced.isdigit() and size != int(announced):
        raise DownloadError(
            f"the download of {source} broke off after {size} of {announced} bytes: "
            "nothing installed (try again)"
        )
    return sha.hexdigest()


def _release_root(unpacked: Path) -> Path:
    """The folder holding snap.html: the archive's own, or its single top folder."""
    if (unpacked / "snap.html").is_file():
        return unpacked
    children = [c for c in unpacked.iterdir()]
    if len(children) == 1 and (children[0] / "snap.html").is_file():
        return children[0]
    raise DownloadError("the archive holds no snap.html (at its top or in its one folder)")


def download(
    version: str | None = None,
    source: str | None = None,
    digest: str | None = None,
    *,
    force: bool = False,
    timeout_s: float = 60.0,
    progress: Callable[[int], None] | None = None,
) -> InstalledSnap:
    """Download a Snap! release once, check it, and install it (atomically) in the data folder.

    Args:
        version: the release (the pinned one by default).
        source: where to get it (an http(s) URL, file:// URL or file; GitHub's by default).
        digest: the release digest it must have (the pin of ``version`` by default).
        force: download again over an installed copy.
        timeout_s: the network timeout.
        progress: called with the bytes downloaded so far.

    Returns:
        The installed copy (``downloaded`` False when it was already there).

    Raises:
        ArgumentError: a version, digest or source that cannot be used.
        DownloadError: the download failed or does not match the digest: nothing installed.
        FileError: the data folder cannot be written.
    """
    release = plan(version, source, digest)
    home = releases_folder()
    target = home / release.version
    present = installed(release.version)
    if present is not None and not force:
        return present
    try:
        home.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileError(f"cannot create {home}: {exc.strerror or exc}", path=str(home)) from None
    work = home / f".download-{secrets.token_hex(6)}"
    try:
        work.mkdir()
        archive = work / "release.archive"
        log.info("downloading Snap! %s from %s", release.version, release.url)
        archive_sha = _fetch(release.url, archive, timeout_s, progress or (lambda _: None))
        unpacked = work / "unpacked"
        unpacked.mkdir()
        unpack(archive, unpacked)
        root = _release_root(unpacked)
        found = release_digest(root)
        if found != release.digest:
            raise DownloadError(
                f"the Snap! release from {release.url} does not match the pinned digest "
                f"(expected {release.digest[:16]}…, got {found[:16]}…): not installed"
            )
        facts = {"version": release.version, "digest": found, "source": release.url}
        facts["archive_sha256"] = archive_sha
        (root / MARKER).write_text(json.dumps(facts, indent=2) + "\n", encoding="utf-8")
        _put_in_place(root, target, work)
    except OSError as exc:
        raise FileError(f"cannot install Snap! in {home}: {exc.strerror or exc}") from None
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return InstalledSnap(release.version, target, found, release.url, archive_sha, True)


def _put_in_place(root: Path, target: Path, work: Path) -> None:
    """Rename the checked copy into place; an older copy is swapped out, then removed."""
    old = work / "previous"
    had_old = target.exists()
    if had_old:
        os.rename(target, old)
    try:
        os.rename(root, target)
    except OSError:
        if had_old:
            os.rename(old, target)
        raise
