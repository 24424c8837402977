"""``SensorChannels``: the skeletons (Kinect, camera pose) and the IMUs on Foxglove channels.

Per skeleton sensor (``KinectSensor``, ``PoseSkeleton``: a ``tracked_skeleton`` register)
``/NAME/skeletons`` (``foxglove.SceneUpdate``); per IMU ``/NAME/imu``
(``foxglove.FrameTransform``, its orientation) and ``/NAME/imu/values`` (JSON
``poppy.ImuValues``: yaw, pitch, roll, the quaternion, rates and accelerations). A sensor is
started when a sink wants one of its channels; its messages go out once it has a value (its
health's ``age_s``: the state loop never waits for a first read), when they change and every
second while they do not.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

from foxglove import Channel, Context, Schema
from foxglove.channels import FrameTransformChannel, SceneUpdateChannel

from poppy_core.errors import SensorError
from poppy_core.server.foxglove import sensor_messages as messages

if TYPE_CHECKING:
    from poppy_core.robot import Robot

REPEAT_PERIOD_S = 1.0
"""How often unchanged values are logged again."""


class SensorChannels:
    """The channels of ``robot``'s skeleton sensors and IMUs on ``context``."""

    def __init__(self, robot: Robot, context: Context) -> None:
        from poppy_core.sensors import Imu, skeleton_sensors

        sensors = list(robot.sensors)
        self.kinects = {
            s.name: (s, SceneUpdateChannel(f"/{s.name}/skeletons", context=context))
            for s in skeleton_sensors(sensors)
        }
        values_schema = Schema(
            name="poppy.ImuValues",
            encoding="jsonschema",
            data=json.dumps(messages.IMU_VALUES_SCHEMA).encode(),
        )
        self.imus = {
            s.name: (
                s,
                FrameTransformChannel(f"/{s.name}/imu", context=context),
                Channel(
                    f"/{s.name}/imu/values",
                    schema=values_schema,
                    message_encoding="json",
                    context=context,
                ),
            )
            for s in sensors
            if isinstance(s, Imu)
        }
        self._last: dict[str, tuple[float, Any]] = {}
        """Sensor name -> (when logged, what): unchanged values wait a second."""
        self._users: dict[str, set[Any]] = {}
        """Kinect name -> the users in its last scene (the ones gone are deleted)."""

    def channels(self) -> list[Any]:
        """Every channel."""
        out: list[Any] = [c for _, c in self.kinects.values()]
        for _, transform, values in self.imus.values():
            out += [transform, values]
        return out

    def reset(self) -> None:
        """A sink started listening: everything again at the next tick."""
        self._last = {}

    def publish(self, wall: float) -> None:
        """Log each sensor's values that changed (or are a second old), if it has some."""
        for name, (kinect, scene) in self.kinects.items():
            try:
                if self._ready(kinect, scene):
                    self._publish_skeletons(name, kinect, scene, wall)
            except SensorError:  # failed for good or closed: its health says why
                continue
        for name, (imu, transform, values) in self.imus.items():
            try:
                if self._ready(imu, transform, values):
                    self._publish_imu(name, imu, transform, values, wall)
            except SensorError:
                continue

    def _ready(self, sensor: Any, *channels: Any) -> bool:
        """Someone listens, the sensor runs (started here) and it has read a value."""
        if not any(c.has_sinks() for c in channels):
            return False
        sensor.start()  # idempotent and quick: its thread reads the device
        return sensor.health().age_s is not None

    def _due(self, name: str, value: Any, wall: float) -> bool:
        last = self._last.get(name)
        if last is not None and last[1] == value and wall - last[0] < REPEAT_PERIOD_S:
            return False
        self._last[name] = (wall, value)
        return True

    def _publish_skeletons(self, name: str, kinect: Any, scene: Any, wall: float) -> None:
        skeletons = kinect.tracked_skeleton
        if not self._due(name, skeletons, wall):
            return
        users = set(skeletons)
        gone = sorted(self._users.get(name, set()) - users, key=str)
        self._users[name] = users
        scene.log(messages.skeletons_scene(skeletons, gone, name, wall))

    def _publish_imu(self, name: str, imu: Any, transform: Any, values: Any, wall: float) -> None:
        registers = (imu.orientation, imu.quaternion, imu.angular_velocity, imu.acceleration)
        if not self._due(name, registers, wall):
            return
        transform.log(messages.imu_transform(registers[1], name, wall))
        values.log(messages.imu_values(*registers, wall))
