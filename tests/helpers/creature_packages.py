"""The Poppy creature packages' primitives for the tests: from PyPI, never committed.

``pip download --no-deps poppy-ergo-jr==4.0.2`` (poppy-torso 3.0.0, poppy-humanoid 3.0.0) fetches
each distribution once into ``$POPPY_TEST_CACHE`` (default ``~/.cache/poppy-tests``; not
``$XDG_CACHE_HOME``, which tests/conftest.py points at a temporary folder per worker). At test
time the modules of its ``primitives/`` folder are read out of the archive and written to a
temporary package with their pypot imports changed to poppy's names (docs/pypot.md): the import
lines, and the module path ``pypot.primitive.`` where a body spells it. Without the archive (no
registry) a test fails on CI (``CI`` set) and is skipped elsewhere.
"""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from pathlib import Path
from types import ModuleType

from poppy_core.files import write_file
from tests.helpers.pypot_files import DOWNLOAD_ERRORS, needed

# pypot's module -> poppy's: every pypot name these primitives import is in poppy_core.motion.
_FROM_IMPORT = re.compile(r"^(\s*)from pypot\.primitive(?:\.utils|\.move)? import ", re.M)
_IMPORT = re.compile(r"^(\s*)import pypot\.primitive\s*$", re.M)
_PATH = re.compile(r"\bpypot\.primitive\.")


def cache_folder() -> Path:
    """Where the downloaded distributions are kept between runs."""
    configured = os.environ.get("POPPY_TEST_CACHE")
    base = Path(configured) if configured else Path.home() / ".cache" / "poppy-tests"
    return base / "creatures"


def to_poppy(source: str) -> str:
    """A primitives module with its pypot imports changed to poppy's names."""
    source = _FROM_IMPORT.sub(r"\1from poppy_core.motion import ", source)
    source = _IMPORT.sub(r"\1import poppy_core.motion", source)
    return _PATH.sub("poppy_core.motion.", source)


def _archive(distribution: str, version: str) -> Path:
    folder = cache_folder()
    stem = distribution.replace("-", "_")
    found = sorted(folder.glob(f"{stem}-{version}*")) if folder.is_dir() else []
    if found:
        return found[0]
    with tempfile.TemporaryDirectory(prefix="creature-download-") as scratch:
        command = [
            sys.executable,
            "-m",
            "pip",
            "download",
            "--no-deps",
            "--disable-pip-version-check",
        ]
        command += ["-q", f"{distribution}=={version}", "-d", scratch]
        done = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
        archives = sorted(Path(scratch).iterdir())
        if done.returncode != 0 or not archives:
            raise RuntimeError(f"`{' '.join(command[2:])}` failed: {done.stderr.strip()[-300:]}")
        target = folder / archives[0].name
        write_file(target, archives[0].read_bytes(), replace=True, make_folder=True)
        return target


def _primitive_sources(archive: Path, package: str) -> dict[str, str]:
    """Module name -> source of each ``<package>/primitives/*.py`` in a wheel or an sdist."""
    inside = re.compile(rf"(?:^|/){package}/primitives/(\w+)\.py$")
    found: dict[str, str] = {}
    if archive.suffix in (".whl", ".zip"):
        with zipfile.ZipFile(archive) as zipped:
            for member in zipped.namelist():
                if match := inside.search(member):
                    found[match[1]] = zipped.read(member).decode("utf-8")
    else:
        with tarfile.open(archive) as tarred:
            for info in tarred.getmembers():
                match = inside.search(info.name)
                extracted = tarred.extractfile(info) if info.isfile() else None
                if match and extracted is not None:
                    found[match[1]] = extracted.read().decode("utf-8")
    found.pop("__init__", None)
    if not found:
        raise RuntimeError(f"{archive.name} holds no {package}/primitives/ modules")
    return found


def creature_primitives(
    distribution: str, version: str, package: str, folder: Path
) -> dict[str, ModuleType]:
    """Module name -> the package's primitives module, imported from ``folder`` as poppy runs it."""
    try:
        sources = _primitive_sources(_archive(distribution, version), package)
    except DOWNLOAD_ERRORS as exc:
        needed(
            f"{distribution} {version} is needed (PyPI through pip download, cached in "
            f"{cache_folder()}): {exc}"
        )
    replay = f"replayed_{package}"
    write_file(folder / replay / "__init__.py", "", make_folder=True)
    for name, source in sources.items():
        write_file(folder / replay / f"{name}.py", to_poppy(source))
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    for loaded in [m for m in sys.modules if m == replay or m.startswith(f"{replay}.")]:
        del sys.modules[loaded]
    importlib.invalidate_caches()
    return {name: importlib.import_module(f"{replay}.{name}") for name in sources}
