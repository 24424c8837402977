"""`poppy demo`: the virtual Ergo Jr is scanned, shown, then dances and the command ends."""

from __future__ import annotations

from typing import Any


def test_demo_quick_finishes(poppy: Any) -> None:
    result = poppy("demo", "--quick", "--no-wire-timing", timeout=60)
    assert result.code == 0, result.stderr
    assert "Virtual Poppy Ergo Jr" in result.stdout
    assert "dancing" in result.stdout
    assert "done" in result.stdout
