"""The simulated Ergo Jr fixture of the test modules, built one way (``ergo_fixture``)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, Literal

import pytest

from poppy_core import from_profile
from poppy_core.robot import Robot


def ergo_fixture(
    *,
    scope: Literal["function", "module"] = "function",
    sim: bool | str = True,
    stiff: bool = False,
    home: bool = False,
    **options: Any,
) -> Any:
    """A fixture giving a simulated Ergo Jr, closed after the test (or the module).

    Args:
        scope: pytest's scope of the fixture.
        sim: True (ideal servos, in-process link) or ``"mujoco"``.
        stiff: torque on (``compliant = False``).
        home: stiff, and every motor sent to 0° before the test.
        **options: passed to ``from_profile`` (``sensors=False``, ``creature=False``...).
    """

    @pytest.fixture(scope=scope)
    def ergo() -> Iterator[Robot]:
        with from_profile("ergo-jr", sim=sim, **options) as robot:
            if stiff or home:
                robot.compliant = False
            if home:
                robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.3, wait=True)
            yield robot

    return ergo
