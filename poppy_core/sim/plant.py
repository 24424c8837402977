"""MujocoPlant: the emulator's Plant protocol over one shared MuJoCo world (one view per bus)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from poppy_core.emulator.motor import VirtualMotor
from poppy_core.errors import ConfigError

if TYPE_CHECKING:
    from poppy_core.sim.world import Simulation


@dataclass(frozen=True)
class MotorJoint:
    """The joint one motor drives.

    The joint's angle is the motor's own angle, the one its control table holds (poppy's models
    are built so, see ``poppy_core.sim.mjcf``): orientation and offset stay the ``Motor``'s
    business, on the robot's side of the bus, as with a real servo.
    """

    joint: str


class MujocoPlant:
    """The motors of one bus, moved by the joints of a :class:`Simulation`.

    The physics runs in the simulation's own thread, which reads the motors' commands and writes
    their sensed state through the control tables (under ``motor.lock``). :meth:`step` is
    therefore a no-op: the bus sees the physics only through the tables. Without the thread
    (tests), ``Simulation.advance(dt)`` steps the world and the tables together: commands are
    read at every call, the sensed state is written every ``STATE_PERIOD_S`` (10 ms) of
    simulated time.

    Args:
        simulation: the world shared by every bus of the robot.
        links: motor id -> its joint.
    """

    def __init__(self, simulation: Simulation, links: Mapping[int, MotorJoint]) -> None:
        self.simulation = simulation
        self.links = dict(links)

    def attach(self, motors: Sequence[VirtualMotor]) -> None:
        """Bind each motor to its joint (by the motor's id) and start it at the joint's pose.

        Raises:
            ConfigError: a motor has no joint, or the joint is not in the model.
        """
        for motor in motors:
            link = self.links.get(motor.id)
            if link is None:
                raise ConfigError(
                    f"motor {motor.id} has no joint in the simulation", field="motors"
                )
            self.simulation.bind(motor, link)
            motor.hand_mover = self._move_by_hand

    def step(self, dt_s: float) -> None:
        """Nothing to do: the simulation's thread advances the physics (see the class doc)."""

    def _move_by_hand(self, motor: VirtualMotor, position_deg: float) -> None:
        self.simulation.set_joint_deg(self.links[motor.id].joint, position_deg)
        motor.table.set_si("present_position", position_deg)
