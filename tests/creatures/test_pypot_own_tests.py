"""pypot 5.0.2's own tests (test_primitive, test_crashed_prim, test_dummy), run on poppy with only
their import lines changed.

pypot's file is not part of this repository, and neither pypot's wheel nor its sdist on PyPI
ships its tests, while the machines the suite runs on reach only the package registries. So the
file is read from a cache (``$POPPY_TEST_CACHE``, else ``~/.cache/poppy-tests``) where a
developer puts it from a clone of pypot's repository at the 5.0.2 tag (the skip says how), and
checked by its SHA-256; without it the test skips and says so.
"""

from __future__ import annotations

import hashlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

PYPOT_TAG = "5.0.2"
PYPOT_COMMIT = "82e8337c79fbf49533ae6736af7304b65e0a6d7d"  # git rev-parse 5.0.2^{commit}
SOURCES = {
    "test_primitive.py": "292ff87263047c24c1f3a8ad44af1f7d14a3046ac663fbd450510b3119332885",
    "test_crashed_prim.py": "4b9dec42d798151dca69dee97f9ce476d83b71195d639331caf47fdef18cdb28",
    "test_dummy.py": "b220809e67e057199214d2e82d25703547862bdccedbcd4dc8133d1e41a51d34",
}
# The import lines changed, as a pypot user changes them (every other line runs as written).
IMPORTS = {
    "from pypot.creatures import PoppyErgoJr": "from poppy_core.pypot import PoppyErgoJr",
    "from pypot.primitive import LoopPrimitive": "from poppy_core.motion import LoopPrimitive",
    "from pypot.robot.controller import MotorsController": (
        "from poppy_core.robot.controller import MotorsController"
    ),
}
# Every test of those files passes but one, on purpose (docs/pypot.md, "What behaves
# differently"): test_dummy_controller sets moving_speed 10000 and expects every motor at its goal
# one sync later; pypot's dummy moved at 10000°/s, poppy's virtual servos at their model's top
# speed (681°/s on an XL-320, the register's cap, as pypot's real motors), so 25° takes 2-3 syncs.
EXPECTED_FAILURES = {"test_dummy_controller"}
RESULT = re.compile(r"^(test_\w+) \([\w.]+\) \.\.\. (ok|FAIL|ERROR)$", re.M)
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
def test_pypot_own_tests_pass_with_the_imports_changed(tmp_path: Path) -> None:
    modules = []
    for name in SOURCES:
        source = pypot_test_file(name).read_text(encoding="utf-8")
        for pypot_line, poppy_line in IMPORTS.items():
            source = source.replace(pypot_line, poppy_line)
        ours = source.replace("pypot_", "").replace("poppy_core.pypot", "")
        assert "pypot" not in ours, f"{name}: an import left unchanged"
        module = f"pypot_{name.removesuffix('.py')}"
        (tmp_path / f"{module}.py").write_text(source, encoding="utf-8")
        modules.append(module)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), str(tmp_path)])}
    try:
        run = subprocess.run(
            [sys.executable, "-m", "unittest", "-v", *modules],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=RUN_TIMEOUT_S,
        )
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"pypot's tests hung ({RUN_TIMEOUT_S:g} s):\n{exc.stderr!s}")
    results = dict(RESULT.findall(run.stderr))
    assert "Ran 7 tests" in run.stderr, run.stderr
    failed = {test for test, outcome in results.items() if outcome != "ok"}
    assert len(results) == 7 and failed == EXPECTED_FAILURES, run.stderr
