"""`make run` and `make test` say what they install before the minute pip takes."""

from __future__ import annotations

import re
import shlex
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


def test_make_test_runs_mypy_and_the_gl_tests_beside_the_parallel_suite(tmp_path: Path) -> None:
    """Every part of `make test` is still run: lint, then the suite's two parts (the modules
    that mostly wait in three workers of their own), mypy and the OpenGL tests at the same time
    (tests/together.sh, whose status is the first failing part's)."""
    lines = make_dry_run("test", tmp_path).stdout.replace("\\\n", " ").splitlines()
    together = next(line for line in lines if "tests/together.sh" in line)
    assert "ruff check" in lines[lines.index(together) - 2]
    assert "ruff format --check" in lines[lines.index(together) - 1]
    parts = [re.sub(r"\S*/(?=pytest|mypy)", "", part) for part in shlex.split(together)[2:]]
    assert parts == [
        'env POPPY_TEST_PART=rest pytest -m "not gl" -n auto --dist loadgroup',
        'env POPPY_TEST_PART=waiting pytest -m "not gl" -n 3 --dist loadgroup',
        "mypy",
        "env POPPY_TEST_PART=gl pytest -m gl",
    ]


def together(*commands: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["sh", str(ROOT / "tests" / "together.sh"), *commands],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def test_together_fails_when_a_command_beside_the_main_one_fails() -> None:
    done = together("echo main", 'sh -c "echo broken; exit 3"', "echo fine")
    assert done.returncode == 3, done
    assert done.stdout.splitlines() == [
        "echo main",
        "main",
        "",
        '==== sh -c "echo broken; exit 3" (exit 3) ====',
        "broken",
        "",
        "==== echo fine (exit 0) ====",
        "fine",
        "",
        "==== recap ====",
        "echo main (exit 0)",
        'sh -c "echo broken; exit 3" (exit 3)',
        "echo fine (exit 0)",
    ]


def test_together_recaps_the_failed_tests_last() -> None:
    # a CI summary shows only the log's tail: the failures of the main command must be in it
    main = (
        'sh -c "echo FAILED tests/a.py::t - boom; echo; echo \\"== 1 failed in 2.5s ==\\"; exit 1"'
    )
    done = together(main, 'sh -c "echo ERROR tests/b.py; echo; exit 2"')
    assert done.returncode == 1, done
    recap = done.stdout.splitlines()
    assert recap[recap.index("==== recap ====") + 1 :] == [
        f"{main} (exit 1)",
        "    FAILED tests/a.py::t - boom",
        "    == 1 failed in 2.5s ==",
        'sh -c "echo ERROR tests/b.py; echo; exit 2" (exit 2)',
        "    ERROR tests/b.py",
    ]


def test_together_exits_with_the_main_commands_failure_first() -> None:
    assert together("exit 4", "false").returncode == 4
    assert together("true", "true").returncode == 0
