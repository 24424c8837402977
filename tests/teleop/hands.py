"""A test "hand": moves the joints of a simulated robot as a person moves a compliant arm.

The emulator's ``move_by_hand`` sets the virtual servo's horn; the robot reads it over the bus
as it would read a real arm pushed by hand (see ``poppy demo`` and the record tests).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping

from poppy_core.emulator import VirtualMotor
from poppy_core.robot import Robot
from tests.helpers.waiting import scaled

READ_S = 0.06
"""Long enough for the 50 Hz sync loop to read a new position at least twice."""


class Hand:
    """Moves the joints of ``robot`` (built with ``sim=True``) in its user frame."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.buses = {name: server.bus for name, server in robot.emulators.items()}

    def _virtual(self, name: str) -> VirtualMotor:
        motor = self.robot.motor(name)
        for bus in self.buses.values():
            try:
                return bus.motor(motor.id)
            except KeyError:
                continue
        raise KeyError(name)

    def put(self, positions: Mapping[str, float]) -> None:
        """Put joints at user-frame angles (the robot's current offsets and orientations)."""
        for name, degrees in positions.items():
            self.put_motor_frame(name, self.robot.motor(name).to_motor(degrees))

    def put_motor_frame(self, name: str, degrees: float) -> None:
        """Put a joint at a motor-frame angle (what the servo itself reads)."""
        self._virtual(name).move_by_hand(degrees)

    def goal_motor_frame(self, name: str) -> float:
        """The goal the servo of ``name`` holds (motor frame)."""
        return float(self._virtual(name).goal_position_deg)

    def goal(self, name: str) -> float:
        """The goal the servo of ``name`` holds, in the robot's user frame."""
        return self.robot.motor(name).to_user(self.goal_motor_frame(name))

    def unplug(self, name: str) -> None:
        """Disconnect a joint's servo (silence on the bus)."""
        motor = self.robot.motor(name)
        for bus in self.buses.values():
            bus.unplug(motor.id)

    def plug(self, name: str) -> None:
        """Reconnect it."""
        motor = self.robot.motor(name)
        for bus in self.buses.values():
            bus.plug(motor.id)


def wait_for(
    condition: Callable[[], object], timeout_s: float = 5.0, period_s: float = 0.01
) -> bool:
    """Poll ``condition()`` until it is true or ``timeout_s`` times the load factor ran out
    (returns its last value)."""
    deadline = time.monotonic() + scaled(timeout_s)
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(period_s)
    return bool(condition())
