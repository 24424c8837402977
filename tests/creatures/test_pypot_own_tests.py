"""pypot 5.0.2's own tests/test_primitive.py, run on poppy with only its import lines changed.

pypot's file is not part of this repository, and neither pypot's wheel nor its sdist on PyPI
ships its tests, while the machines the suite runs on reach only the package registries. So the
file is read from a cache (``$POPPY_TEST_CACHE``, else ``~/.cache/poppy-tests``) where a
developer puts it from a clone of pypot's repository at the 5.0.2 tag (the skip says how), and
checked by its SHA-256; without it the test skips and says so.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

PYPOT_TAG = "5.0.2"
PYPOT_COMMIT = "82e8337c79fbf49533ae6736af7304b65e0a6d7d"  # git rev-parse 5.0.2^{commit}
SOURCES = {
    "test_primitive.py": "292ff87263047c24c1f3a8ad44af1f7d14a3046ac663fbd450510b3119332885",
}
# The import lines changed, as a pypot user changes them (every other line runs as written).
IMPORTS = {
    "from pypot.creatures import PoppyErgoJr": "from poppy_core.creatures import PoppyErgoJr",
    "from pypot.primitive import LoopPrimitive": "from poppy_core.motion import LoopPrimitive",
}
REPO_ROOT = Path(__file__).resolve().parents[2]
RUN_TIMEOUT_S = 90.0  # under pytest-timeout's 120 s: a hang is reported as one


def _cache_dir() -> Path:
    # Not $XDG_CACHE_HOME: tests/conftest.py points it at a temporary folder per worker.
    configured = os.environ.get("POPPY_TEST_CACHE")
    base = Path(configured) if configured else Path.home() / ".cache" / "poppy-tests"
    return base / f"pypot-{PYPOT_TAG}"


def pypot_test_file(name: str) -> Path:
    """pypot's ``tests/<name>`` at 5.0.2 from the cache (hash checked), or a skip saying how."""
    path = _cache_dir() / name
    expected = SOURCES[name]
    if not path.is_file():
        pytest.skip(
            f"pypot {PYPOT_TAG}'s tests/{name} is not at {path}: put it there with "
            f"`git -C <pypot clone> show {PYPOT_COMMIT}:tests/{name} > {path}`"
        )
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != expected:
        pytest.fail(f"{path} is not pypot {PYPOT_TAG}'s file (sha256 {digest})", pytrace=False)
    return path


@pytest.mark.slow
def test_pypot_test_primitive_passes_with_the_import_changed(tmp_path: Path) -> None:
    source = pypot_test_file("test_primitive.py").read_text(encoding="utf-8")
    for pypot_line, poppy_line in IMPORTS.items():
        assert pypot_line in source, f"pypot's file no longer has {pypot_line!r}"
        source = source.replace(pypot_line, poppy_line)
    replay = tmp_path / "pypot_test_primitive.py"
    replay.write_text(source, encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), str(tmp_path)])}
    try:
        run = subprocess.run(
            [sys.executable, "-m", "unittest", "-v", "pypot_test_primitive"],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=RUN_TIMEOUT_S,
        )
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"pypot's test_primitive.py hung ({RUN_TIMEOUT_S:g} s):\n{exc.stderr!s}")
    assert run.returncode == 0, run.stderr
    assert "Ran 4 tests" in run.stderr and "OK" in run.stderr
