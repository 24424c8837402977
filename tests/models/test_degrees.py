"""Degrees as shown: the decimals of the motor's resolution, never ``-0`` (issue 40)."""

from __future__ import annotations

import pytest

from poppy_core.models import model_by_name
from poppy_core.models.degrees import decimals, fmt_deg, tick_deg


@pytest.mark.parametrize(
    ("model", "places"), [("XL-320", 1), ("AX-12A", 1), ("MX-28", 2), ("MX-64", 2)]
)
def test_the_decimals_are_the_motor_s_resolution(model: str, places: int) -> None:
    step = tick_deg(model_by_name(model))
    assert decimals(step) == places
    shown = fmt_deg(149.70703125, step)
    assert shown == f"{149.70703125:.{places}f}°"


@pytest.mark.parametrize("value", [-0.0, -0.01, -0.04, -0.4])
def test_never_minus_zero(value: float) -> None:
    assert fmt_deg(value, 1.0, "") == "0"
    assert not fmt_deg(value / 10, 0.29).startswith("-")


def test_a_value_keeps_its_sign_and_unit() -> None:
    assert fmt_deg(-30.0, 0.29) == "-30.0°"
    assert fmt_deg(12.34, 1.0, " deg") == "12 deg"
    assert decimals(0.01) == 2 and decimals(1.0) == 0 and decimals(0.0) == 1


def test_fleet_status_shows_no_minus_zero() -> None:
    import io
    import time
    from types import SimpleNamespace

    from rich.console import Console

    from poppy_cli.commands.fleet_zenoh import _status_table

    motors = {
        "m1": {"present_position": -0.3, "online": True},
        "m2": {"present_position": -29.6, "online": True},
    }
    state = SimpleNamespace(motors=motors, stamp=time.time())
    table = _status_table({"poppy": True}, {"poppy": state}, {"poppy": {"ok": True}})
    out = io.StringIO()
    Console(file=out, width=200).print(table)
    assert "m1:0 " in out.getvalue() and "m2:-30" in out.getvalue()
    assert "-0" not in out.getvalue().replace("m2:-30", "")
