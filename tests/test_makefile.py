"""`make run` and `make test` say what they install before the minute pip takes."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def make_dry_run(target: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    """What ``make -n -B TARGET`` would run with a fresh virtualenv (skips without make)."""
    if shutil.which("make") is None:
        pytest.skip("no make here")
    done = subprocess.run(
        ["make", "-n", "-B", target, f"VENV={tmp_path / '.venv'}"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return done


@pytest.mark.parametrize("target", ["run", "test"])
def test_make_says_it_is_installing_before_pip_runs(target: str, tmp_path: Path) -> None:
    done = make_dry_run(target, tmp_path)
    lines = done.stdout.splitlines()
    install = next(i for i, line in enumerate(lines) if "pip install --quiet -e" in line)
    said = [line for line in lines[:install] if line.startswith("echo ")]
    assert said, lines
    assert "installing poppy" in said[-1] and "minute" in said[-1]


@pytest.mark.parametrize(("target", "extras"), [("run", "[all]"), ("test", "[all,test]")])
def test_make_installs_every_extra(target: str, extras: str, tmp_path: Path) -> None:
    """The bare package is the core only (a Raspberry Pi's install): a newcomer's `make run`
    and `make test` still get every room (pyproject's `all` extra)."""
    done = make_dry_run(target, tmp_path)
    install = [line for line in done.stdout.splitlines() if "pip install --quiet -e" in line]
    assert install and install[-1].endswith(f"-e '.{extras}'"), install
