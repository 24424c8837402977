"""Print pypot's answers to the documented DxlIO calls; tests/bus/test_dxlio.py keeps them.

Run it with the peers venv against an emulated bus::

    poppy emulate --motors MX-28:4-6,AX-12A:11        # prints the pty, e.g. /dev/pts/3
    bench/.venv-peers/bin/python bench/peers/pypot_dxlio_calls.py /dev/pts/3

One line per call, ``call -> answer`` (or the error), in the order of ``PYPOT_ANSWERS``. A read
right after pypot's write answered the old value on the emulated bus (pypot does not wait for the
write's status), so each ``set`` is given a moment before the ``get``.
"""

from __future__ import annotations

import importlib
import sys
import time
from collections.abc import Callable
from typing import Any

SETTLE_S = 0.1


def _then(first: Callable[[], Any], second: Callable[[], Any]) -> Any:
    first()
    time.sleep(SETTLE_S)
    return second()


def calls(io: Any) -> list[tuple[str, Callable[[], Any]]]:
    """The calls, named as the test names them."""
    return [
        ("get_control_mode([4, 11])", lambda: io.get_control_mode([4, 11])),
        (
            "set_wheel_mode([5]); get_control_mode([5])",
            lambda: _then(lambda: io.set_wheel_mode([5]), lambda: io.get_control_mode([5])),
        ),
        (
            "set_joint_mode([5]); get_control_mode([5])",
            lambda: _then(lambda: io.set_joint_mode([5]), lambda: io.get_control_mode([5])),
        ),
        ("get_angle_limit([11])", lambda: io.get_angle_limit([11])),
        ("get_pid_gain([4])", lambda: io.get_pid_gain([4])),
        (
            "get_pid_gain([4]) after set_pid_gain({4: (4, 2, 1)})",
            lambda: _then(lambda: io.set_pid_gain({4: (4, 2, 1)}), lambda: io.get_pid_gain([4])),
        ),
        ("get_compliance_margin([11])", lambda: io.get_compliance_margin([11])),
        ("get_compliance_slope([11])", lambda: io.get_compliance_slope([11])),
        ("get_goal_position_speed_load([4, 11])", lambda: io.get_goal_position_speed_load([4, 11])),
        (
            "get_present_position_speed_load([4, 11])",
            lambda: io.get_present_position_speed_load([4, 11]),
        ),
        ("get_alarm_shutdown([4, 11])", lambda: io.get_alarm_shutdown([4, 11])),
        ("get_alarm_LED([4, 11])", lambda: io.get_alarm_LED([4, 11])),
        ("get_voltage_limit([4, 11])", lambda: io.get_voltage_limit([4, 11])),
        (
            "get_voltage_limit([4]) after set_voltage_limit({4: (7.0, 15.0)})",
            lambda: _then(
                lambda: io.set_voltage_limit({4: (7.0, 15.0)}), lambda: io.get_voltage_limit([4])
            ),
        ),
        (
            "get_highest_temperature_limit([4, 11])",
            lambda: io.get_highest_temperature_limit([4, 11]),
        ),
        ("get_drive_mode([4])", lambda: io.get_drive_mode([4])),
        ("get_status_return_level([4, 11])", lambda: io.get_status_return_level([4, 11])),
        ("get_control_table([4]) keys", lambda: tuple(io.get_control_table([4])[0])),
        (
            "get_moving_speed([4]) after set_moving_speed({4: 10000})",
            lambda: _then(
                lambda: io.set_moving_speed({4: 10000}), lambda: io.get_moving_speed([4])
            ),
        ),
    ]


def main() -> None:
    """Open the port with pypot's DxlIO and print each call's answer."""
    dynamixel = importlib.import_module("pypot.dynamixel")
    io = dynamixel.DxlIO(sys.argv[1], baudrate=1_000_000)
    try:
        for name, call in calls(io):
            try:
                print(f"{name} -> {call()!r}")
            except Exception as exc:  # a peer's failure is an answer too
                print(f"{name} -> {type(exc).__name__}: {exc}")
    finally:
        io.close()


if __name__ == "__main__":
    main()
