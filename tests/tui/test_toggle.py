"""The TUI's toggle keys write what ``Register.switched`` says (an XL-320 LED goes white/off)."""

from __future__ import annotations

from poppy_cli.tui.ops import toggled
from poppy_core.models import AX_12A, XL_320


def test_toggle_flips_booleans_and_led_colours() -> None:
    led = XL_320.register("led")
    assert toggled(None, led) == "white" and toggled("off", led) == "white"
    assert toggled("red", led) == "off" and toggled("white", led) == "off"
    torque = AX_12A.register("torque_enable")
    assert toggled(None, torque) is True and toggled(False, torque) is True
    assert toggled(True, torque) is False
