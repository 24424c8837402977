"""``SimIMU``: an IMU riding a body of the MuJoCo world, read as a real one (same registers).

The IMU is mounted on its body level with the world when every joint is at 0 (the model's
reference pose: the robot standing, head straight), x along the world's x and z up, as one
mounts a real IMU; it reads the orientation of that mount in the world, its angular velocity
and the specific force an accelerometer there measures (its acceleration minus gravity: +9.81
m/s² up when still), in the mount's frame; see ``poppy_core.sensors.imu`` for the frame and
units.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco  # noqa: TID253 (this room is imported lazily, by the factory)
import numpy as np

from poppy_core.errors import ConfigError
from poppy_core.sensors.config import ImuMaker, SensorSpec
from poppy_core.sensors.imu import Imu, angles_of

DEFAULT_BODY = "head"


class SimIMU(Imu):
    """An IMU on body ``body`` of ``simulation``.

    Args:
        name: the sensor's name.
        simulation: the world (``robot.simulation``).
        body: the body it rides (default: ``head``).
        rate_hz: reads per second.

    Raises:
        ConfigError: the world has no such body (the message lists them).
    """

    def __init__(self, name: str, simulation: Any, body: str | None, rate_hz: float) -> None:
        super().__init__(name, rate_hz)
        self._sim = simulation
        chosen = body or DEFAULT_BODY
        index = mujoco.mj_name2id(simulation.model, mujoco.mjtObj.mjOBJ_BODY, chosen)
        if index < 0:
            known = ", ".join(simulation.body_names())
            raise ConfigError(
                f"sensor {name!r}: the simulation has no body {chosen!r}: set its "
                f"'sim_body' to one of {known}",
                field=f"sensors.{name}.sim_body",
            )
        self.body = chosen
        self._index = int(index)
        self._motion = np.zeros(6)
        reference = mujoco.MjData(simulation.model)
        mujoco.mj_kinematics(simulation.model, reference)
        self._home = np.array(reference.xquat[self._index])
        """The body's orientation at the reference pose: the mount is its inverse."""
        self._mount = np.zeros(4)
        mujoco.mju_negQuat(self._mount, self._home)
        # MuJoCo gives a body's velocity and acceleration in its inertial frame (centre of
        # mass, principal axes): this turns them into the mount's
        self._inertial_to_mount = np.zeros(4)
        mujoco.mju_mulQuat(self._inertial_to_mount, self._home, simulation.model.body_iquat[index])

    def update(self) -> bool | None:
        sim = self._sim
        model, data, index, motion = sim.model, sim.data, self._index, self._motion
        with sim.lock:
            body = np.array(data.xquat[index])
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, index, motion, 1)
            rates = np.array(motion[:3])
            # the bodies' accelerations (cacc) are computed on demand, as MuJoCo's own
            # accelerometer sensors have them computed; the world's state does not change
            mujoco.mj_rnePostConstraint(model, data)
            mujoco.mj_objectAcceleration(model, data, mujoco.mjtObj.mjOBJ_BODY, index, motion, 1)
            accel = np.array(motion[3:])
        mounted = np.zeros(4)
        mujoco.mju_mulQuat(mounted, body, self._mount)
        w, x, y, z = (float(v) for v in mounted)
        self._set(
            angles_of(w, x, y, z), self._in_mount(rates, math.degrees(1)), self._in_mount(accel)
        )
        return None

    def _in_mount(self, local: np.ndarray, scale: float = 1.0) -> tuple[float, float, float]:
        """A vector in the body's inertial frame, in the mount's frame (times ``scale``)."""
        out = np.zeros(3)
        mujoco.mju_rotVecQuat(out, local, self._inertial_to_mount)
        x, y, z = (float(v) * scale for v in out)
        return x, y, z


def sim_imu_maker(simulation: Any) -> ImuMaker:
    """Makes the ``SimIMU`` of a config's IMU entry (``sim_body``: the body it rides)."""

    def make(spec: SensorSpec) -> Imu:
        return SimIMU(spec.name, simulation, spec.sim_body, spec.rate_hz or 50.0)

    return make
