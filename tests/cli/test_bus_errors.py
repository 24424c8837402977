"""A bus that cannot be opened is one port error line, whatever the command searches for."""

from __future__ import annotations

from typing import Any


def test_motor_command_on_a_missing_port_is_a_port_error(poppy: Any) -> None:
    result = poppy("motor", "set", "3", "goal_position", "30", "--port", "/dev/nonexistent")
    assert result.code == 1
    assert result.stderr.strip().count("\n") == 0, result.stderr
    assert "no such port /dev/nonexistent" in result.stderr
    assert "check power and wiring" not in result.stderr
