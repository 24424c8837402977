"""pypot's controllers (``MotorsController``, ``robot._controllers``) and its dummy robot's goals.

pypot's own tests use them (tests/creatures/test_pypot_own_tests.py replays those): a controller
subclass whose setup fails makes ``start()`` raise a ``RuntimeError``; ``_updated`` is set after
each sync; a dummy motor at its goal reads the goal itself.
"""

from __future__ import annotations

import threading
import time

import pytest

from poppy_core.errors import ControllerError
from poppy_core.pypot import PoppyTorso
from poppy_core.robot.controller import MotorsController
from tests.helpers.waiting import eventually


class Counting(MotorsController):
    def setup(self) -> None:
        self.updates = 0
        self.torn_down = False

    def update(self) -> None:
        self.updates += 1

    def teardown(self) -> None:
        self.torn_down = True


def test_a_controller_runs_update_between_setup_and_teardown() -> None:
    controller = Counting(None, [], 50.0)
    controller.start()
    assert controller.running
    controller._updated.clear()
    assert controller._updated.wait(15.0)
    assert eventually(lambda: controller.updates >= 3, 15.0)
    controller.close()
    assert not controller.running and controller.torn_down


def test_a_controller_whose_setup_fails_does_not_start() -> None:
    class Failing(MotorsController):
        def setup(self) -> None:
            raise ValueError("no hardware here")

    with pytest.raises(RuntimeError, match=r"Failing\.setup failed: ValueError") as info:
        Failing(None, [], 50.0).start()
    assert isinstance(info.value, ControllerError)
    assert isinstance(info.value.__cause__, ValueError)


def test_robot_controllers_are_its_buses_and_updated_marks_a_sync() -> None:
    with PoppyTorso(simulator="dummy") as robot:
        controllers = robot._controllers
        assert [len(c.motors) for c in controllers] == [len(robot.motors)]
        assert all(isinstance(c, MotorsController) and c.running for c in controllers)
        before = robot.head_z.present_position
        controllers[0]._updated.clear()
        assert controllers[0]._updated.wait(15.0)
        robot.stop_sync()
        assert not controllers[0].running
        controllers[0].start()  # pypot's controller.start(): the bus syncs again
        assert robot._controllers[0].running
        assert robot.head_z.present_position == pytest.approx(before, abs=1.0)


def test_the_dummy_reads_a_reached_goal_as_the_goal_itself() -> None:
    # The notebook "Decouverte TP3" (a Torso): head_z sent to 90°, then
    # `while head_z.present_position == 90:` waits for someone to move the head. pypot's dummy
    # gave 90 exactly; an AX-12A's position register reads 89.94°.
    with PoppyTorso(simulator="dummy") as robot:
        head_z = robot.head_z
        head_z.goto_position(90, 0.5, wait=True)
        assert eventually(lambda: head_z.present_position == 90, 15.0)
        mover = threading.Timer(0.5, lambda: setattr(head_z, "goal_position", 60))
        mover.start()
        deadline = time.monotonic() + 30.0
        while head_z.present_position == 90 and time.monotonic() < deadline:
            time.sleep(0.01)
        mover.join()
        assert head_z.present_position != 90 and head_z.goal_position == 60
        assert eventually(lambda: head_z.present_position == 60, 15.0)


def test_mujoco_and_real_servos_keep_the_registers_steps() -> None:
    with PoppyTorso(simulator="mujoco") as robot:
        assert not any(m.ideal_plant for m in robot.motors)
