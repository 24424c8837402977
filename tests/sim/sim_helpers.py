"""Helpers for the MuJoCo simulation tests: a world with virtual motors, stepped by hand."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.emulator import VirtualBus, VirtualMotor
from poppy_core.errors import ConfigError, SensorError
from poppy_core.models import model_by_name
from poppy_core.robot.config import MotorConfig
from poppy_core.robot.frames import to_motor, to_user
from poppy_core.robot.profiles import load_profile
from poppy_core.sim.plant import MotorJoint, MujocoPlant
from poppy_core.sim.world import Simulation

ROOT = Path(__file__).resolve().parents[2]
PROFILES = ROOT / "profiles"
ROBOTS = ("ergo-jr", "torso", "humanoid")


@dataclass
class World:
    """A simulation, its motors by name and their config entries (orientation, offset)."""

    sim: Simulation
    motors: dict[str, VirtualMotor]
    entries: dict[str, MotorConfig]

    def command(self, name: str, user_deg: float, torque: bool = True) -> None:
        """Write a goal in poppy's frame (converted to the motor's) and the torque flag."""
        motor, entry = self.motors[name], self.entries[name]
        with motor.lock:
            motor.table.set_si("goal_position", to_motor(user_deg, entry.orientation, entry.offset))
            motor.table.set("torque_enable", int(torque))

    def present_user_deg(self, name: str) -> float:
        """The motor's present position, converted to poppy's frame."""
        entry = self.entries[name]
        return to_user(self.motors[name].present_position_deg, entry.orientation, entry.offset)

    def run(self, seconds: float) -> None:
        """Advance the physics ``seconds`` in 10 ms steps (no thread, deterministic)."""
        for _ in range(round(seconds / 0.01)):
            self.sim.advance(0.01)


def make_world(robot: str) -> World:
    """The robot's model with one virtual bus per controller attached (physics not running)."""
    config = load_profile(robot)
    sim = Simulation.from_file(PROFILES / robot / "model.xml")
    motors: dict[str, VirtualMotor] = {}
    for controller, entry in config.controllers.items():
        ids: dict[int, MotorJoint] = {}
        bus_motors = []
        for name in config.motors_of_controller(controller):
            motor_entry = config.motors[name]
            ids[motor_entry.id] = MotorJoint(name)
            motors[name] = VirtualMotor(model_by_name(motor_entry.type), motor_entry.id)
            bus_motors.append(motors[name])
        VirtualBus(bus_motors, entry.protocol, plant=MujocoPlant(sim, ids), auto_step=False)
    return World(sim, motors, dict(config.motors))


def ready_to_look(robot: Any) -> Any:
    """``robot`` once its camera gave a frame (skips without OpenGL), stiff, every motor at 0°."""
    try:
        robot.camera.latest(timeout_s=30)
    except (SensorError, ConfigError) as exc:
        pytest.skip(f"no OpenGL for offscreen rendering here ({exc}); `make sim-deps`")
    robot.compliant = False
    robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.5, wait=True)
    time.sleep(0.5)
    return robot


def ahead_of_camera(sim: Any, ahead_m: float, right_m: float) -> tuple[float, float, float]:
    """The point ``ahead_m`` in front of the scene's camera and ``right_m`` to its right."""
    import mujoco

    with sim.lock:
        camera = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
        axes = np.asarray(sim.data.cam_xmat[camera]).reshape(3, 3)
        where = np.asarray(sim.data.cam_xpos[camera])
    point = where + ahead_m * -axes[:, 2] + right_m * axes[:, 0]
    return (float(point[0]), float(point[1]), float(point[2]))
