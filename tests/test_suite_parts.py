"""The parts `make test` runs side by side hold the whole suite, each module once."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests import conftest
from tests.helpers import parts

TESTS = Path(__file__).resolve().parent
MODULES = sorted(
    path.relative_to(TESTS).as_posix()
    for path in TESTS.rglob("test_*.py")
    if "__pycache__" not in path.parts
)


def _source(module: str) -> str:
    return (TESTS / module).read_text(encoding="utf-8")


def test_the_waiting_and_the_rest_hold_every_module_once() -> None:
    for module in MODULES:
        kept = [
            part
            for part in ("waiting", "rest")
            if not parts.outside_part(module, part, lambda m=module: _source(m))
        ]
        assert len(kept) == 1, (module, kept)
        assert not parts.outside_part(module, None, lambda: "")  # unset: the whole suite


def test_every_waiting_module_exists_and_none_drives_the_browser() -> None:
    assert set(parts.WAITING_MODULES) <= set(MODULES)
    assert not set(parts.WAITING_MODULES) & conftest.BROWSER_MODULES  # one browser at a time
    assert not set(parts.WAITING_MODULES) & parts.GL_MODULES


def test_the_gl_part_keeps_every_module_that_marks_a_test_gl() -> None:
    kept = {m for m in MODULES if not parts.outside_part(m, "gl", lambda m=m: _source(m))}
    marking = {m for m in MODULES if re.search(r"pytest\.mark\.gl\b", _source(m))}
    assert parts.GL_MODULES | marking == kept
    assert "creatures/test_doc_examples.py" in kept  # one gl test among many


@pytest.mark.parametrize("value", ["", " ", "waiting", "rest", "gl"])
def test_a_part_is_named_or_unset(value: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(parts.PART_ENV, value)
    assert parts.current_part() == (value.strip() or None)


def test_an_unknown_part_is_refused_in_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(parts.PART_ENV, "slow")
    with pytest.raises(parts.UnknownPart, match=r"^POPPY_TEST_PART='slow' names no part.*unset"):
        parts.current_part()
