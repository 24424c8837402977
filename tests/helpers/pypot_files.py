"""pypot 5.0.2's Snap! project files for the tests, never committed: from the peers' venv or PyPI.

On the development machine ``bench/.venv-peers`` holds pypot (``make peers``); elsewhere (CI)
``pip download --no-deps pypot==5.0.2`` fetches its distribution once and the files are read
out of it (a wheel or an sdist) into a cache folder. Without the files a test fails with a
clear message on CI (``CI`` set) and is skipped elsewhere.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from pathlib import Path
from typing import NoReturn

import pytest

from poppy_core.files import write_file

PYPOT_VERSION = "5.0.2"
SNAP_FILES = (
    "pypot-snap-blocks.xml",
    "poppy-demo-project.xml",
    "blocs de base Poppy_FR.xml",
    "poppy-base_demo_FR.xml",
)
"""pypot's shipped Snap! library and example projects (``pypot/server/snap_projects/``)."""

INSIDE = "pypot/server/snap_projects/"
ROOT = Path(__file__).resolve().parents[2]
PEERS = ROOT / "bench" / ".venv-peers"


DOWNLOAD_ERRORS = (
    OSError,
    RuntimeError,
    subprocess.SubprocessError,
    tarfile.TarError,
    zipfile.BadZipFile,
)
"""What a missing, unreachable or damaged distribution raises while it is fetched and read."""


def needed(message: str) -> NoReturn:
    """A file from the package index is missing: fail on CI (which must have it), skip elsewhere."""
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def cache_folder() -> Path:
    """Where the files read out of pypot's distribution are kept between runs."""
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "poppy-tests" / f"pypot-{PYPOT_VERSION}" / "snap_projects"


def _in_peers() -> Path | None:
    for folder in sorted(PEERS.glob("lib/python*/site-packages/pypot/server/snap_projects")):
        if all((folder / name).is_file() for name in SNAP_FILES):
            return folder
    return None


def _extract(archive: Path, target: Path) -> None:
    """Copy the Snap! files out of a wheel or an sdist into ``target``."""
    found: dict[str, bytes] = {}
    if archive.suffix in (".whl", ".zip"):
        with zipfile.ZipFile(archive) as zipped:
            for member in zipped.namelist():
                name = member.rsplit("/", 1)[-1]
                if INSIDE in member and name in SNAP_FILES:
                    found[name] = zipped.read(member)
    else:
        with tarfile.open(archive) as tarred:
            for info in tarred.getmembers():
                name = info.name.rsplit("/", 1)[-1]
                extracted = tarred.extractfile(info) if info.isfile() else None
                if INSIDE in info.name and name in SNAP_FILES and extracted is not None:
                    found[name] = extracted.read()
    missing = [name for name in SNAP_FILES if name not in found]
    if missing:
        raise RuntimeError(f"{archive.name} holds no {', '.join(missing)}")
    for name, data in found.items():
        write_file(target / name, data, replace=True, make_folder=True)


def _download(target: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="pypot-download-") as folder:
        command = [sys.executable, "-m", "pip", "download", "--no-deps"]
        command += ["--disable-pip-version-check", "-q", f"pypot=={PYPOT_VERSION}", "-d", folder]
        done = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
        archives = sorted(Path(folder).iterdir())
        if done.returncode != 0 or not archives:
            raise RuntimeError(f"`{' '.join(command[2:])}` failed: {done.stderr.strip()[-300:]}")
        _extract(archives[0], target)


def snap_project_files() -> dict[str, Path]:
    """Name -> path of each of pypot's Snap! files (fails on CI, skips elsewhere, without them)."""
    folder = _in_peers()
    if folder is None:
        folder = cache_folder()
        if not all((folder / name).is_file() for name in SNAP_FILES):
            try:
                _download(folder)
            except DOWNLOAD_ERRORS as exc:
                needed(
                    f"pypot {PYPOT_VERSION}'s Snap! files are needed (bench/.venv-peers, or "
                    f"PyPI through pip download, cached in {folder}): {exc}"
                )
    return {name: folder / name for name in SNAP_FILES}
