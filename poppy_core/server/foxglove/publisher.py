"""``FoxglovePublisher``: the robot logged on Foxglove channels of one SDK context.

Whatever listens to the context gets the same messages: the WebSocket server (``poppy serve
--foxglove``) and an MCAP file (``poppy record --mcap``). A channel is only written while a
sink wants it (``has_sinks``: a subscribed client, an open file): a camera is opened for a
channel someone watches, never otherwise. Channels:

- ``/joint_states`` (``foxglove.JointStates``): each motor's joint angle (rad), speed (rad/s),
  effort (N·m), at the state rate;
- ``/tf`` (``foxglove.FrameTransforms``): the URDF's tree at those angles, with it;
- ``/robot_description`` (JSON ``{"data": URDF}``): the URDF, when a sink starts listening and
  every few seconds (Foxglove's WebSocket protocol keeps no last message for late clients);
- ``/robot_model`` (``foxglove.SceneUpdate``, files only: ``embed_model``): the URDF's meshes
  embedded, one entity per link, logged once (a file has no server to fetch them from);
- ``/health`` (``foxglove.Log``): every bus and sensor once at the start, then each change;
- per camera ``/NAME/image`` (``foxglove.CompressedImage``, the camera's shared JPEG) and, with
  a marker, face or blob detector on it, ``/NAME/detections`` (``foxglove.ImageAnnotations``);
- per Kinect sensor ``/NAME/skeletons`` (``foxglove.SceneUpdate``), per IMU ``/NAME/imu``
  (``foxglove.FrameTransform``) and ``/NAME/imu/values`` (JSON): ``SensorChannels``.
"""

from __future__ import annotations

import json
import logging
import threading
import time
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from foxglove import Channel, Context, Schema
from foxglove.channels import (
    CompressedImageChannel,
    FrameTransformsChannel,
    ImageAnnotationsChannel,
    JointStatesChannel,
    LogChannel,
    SceneUpdateChannel,
)

from poppy_core import checks
from poppy_core.errors import PoppyError
from poppy_core.schedule import Periodic, RateMeter, TickGuard, Worker
from poppy_core.server.foxglove import robot_messages as messages
from poppy_core.server.foxglove.assets import RobotAssets
from poppy_core.server.foxglove.model_scene import model_scene
from poppy_core.server.foxglove.sensor_channels import SensorChannels
from poppy_core.server.ros2.joints import UrdfJoints

if TYPE_CHECKING:
    from poppy_core.robot import Robot
    from poppy_core.sensors import Camera

logger = logging.getLogger(__name__)

DESCRIPTION_PERIOD_S = 5.0
"""How often the URDF is logged again while someone listens."""
HEALTH_PERIOD_S = 1.0
DETECTIONS_PERIOD_S = 1.0
"""How often unchanged detections are logged again."""
STRING_SCHEMA = {"type": "object", "properties": {"data": {"type": "string"}}}
"""A message of one string, ``data`` (what std_msgs/String holds: the 3D panel reads the
URDF of ``/robot_description`` there)."""


def description_channel(context: Context | None) -> Channel:
    """The ``/robot_description`` channel: the URDF as a JSON std_msgs/String."""
    schema = Schema(
        name="std_msgs/String", encoding="jsonschema", data=json.dumps(STRING_SCHEMA).encode()
    )
    return Channel("/robot_description", schema=schema, message_encoding="json", context=context)


class FoxglovePublisher:
    """The robot on Foxglove channels of ``context``.

    Args:
        robot: the robot.
        context: the SDK context its sinks (server, MCAP writer) listen to.
        name: the robot's name (the health log's ``name``).
        state_rate_hz: joint states and transforms per second.
        embed_model: log the URDF's meshes on ``/robot_model`` (for files).
    """

    def __init__(
        self,
        robot: Robot,
        context: Context,
        name: str,
        *,
        state_rate_hz: float = 50.0,
        embed_model: bool = False,
    ) -> None:
        self.robot = robot
        self.context = context
        self.name = name
        self.state_rate_hz = checks.rate(state_rate_hz, "state_rate_hz")
        self.joints = UrdfJoints(robot)
        self.rate = RateMeter()
        self.published = 0
        """Joint state messages logged."""
        self.state_loop = TickGuard(f"foxglove-{name}")
        self.camera_loop = TickGuard(f"foxglove-camera-{name}")
        self._listening = threading.Event()
        """Set when a sink started listening: the URDF goes out at once."""
        self._health: dict[str, messages.HealthLine] = {}
        self._detected: dict[str, tuple[float, list[Any]]] = {}
        self._model_sent = False
        self.states = JointStatesChannel("/joint_states", context=context)
        self.health = LogChannel("/health", context=context)
        self.tf: FrameTransformsChannel | None = None
        self.description: Channel | None = None
        self.model: SceneUpdateChannel | None = None
        self.assets: RobotAssets | None = None
        """The URDF and its meshes (``package://`` URLs), None without a URDF."""
        if self.joints.description is not None:
            self.tf = FrameTransformsChannel("/tf", context=context)
        if self.joints.urdf is not None and self.joints.description is not None:
            self.assets = RobotAssets(Path(self.joints.description.source), self.joints.urdf)
            if embed_model:
                self.model = SceneUpdateChannel("/robot_model", context=context)
            self.description = description_channel(context)
        self.cameras: dict[str, tuple[Camera, CompressedImageChannel]] = {}
        self.detections: dict[str, ImageAnnotationsChannel] = {}
        for camera in self._cameras():
            self.cameras[camera.name] = (
                camera,
                CompressedImageChannel(f"/{camera.name}/image", context=context),
            )
            if self._detectors(camera):
                self.detections[camera.name] = ImageAnnotationsChannel(
                    f"/{camera.name}/detections", context=context
                )
        self.sensors = SensorChannels(robot, context)
        self._worker = Worker(f"foxglove-{name}", self._publish_loop)
        self._camera_workers = [
            Worker(f"foxglove-camera-{cam}", partial(self._camera_loop, cam))
            for cam in self.cameras
        ]

    @property
    def topics(self) -> list[str]:
        """The channels' topics."""
        return [c.topic() for c in self._channels()]

    def _channels(self) -> list[Any]:
        channels: list[Any] = [self.states, self.health, self.tf, self.description, self.model]
        channels += [c for _, c in self.cameras.values()] + list(self.detections.values())
        channels += self.sensors.channels()
        return [c for c in channels if c is not None]

    @property
    def running(self) -> bool:
        """True while the state loop runs."""
        return self._worker.running

    def listening(self) -> None:
        """A sink started listening to a channel: log the URDF and health again now."""
        self._listening.set()

    def start(self) -> None:
        """Publish in the background."""
        if self.running:
            return
        self._worker.start()
        for worker in self._camera_workers:
            worker.start()

    def stop(self) -> None:
        """Stop publishing (the channels stay: a file is finished by its writer)."""
        self._worker.close()
        for worker in self._camera_workers:
            worker.close()

    def close(self) -> None:
        """Stop and close the channels."""
        self.stop()
        for channel in self._channels():
            channel.close()

    # -- the state loop --------------------------------------------------------------------

    def _publish_loop(self, stopping: threading.Event) -> None:
        schedule = Periodic(1.0 / self.state_rate_hz, time.monotonic())
        next_description = next_health = 0.0
        while not stopping.is_set():
            wait = schedule.next_deadline - time.monotonic()
            if wait > 0 and stopping.wait(wait):
                return
            now = time.monotonic()
            schedule.advance(now)
            wall = time.time()
            if self._listening.is_set():
                self._listening.clear()
                next_description = now
                self._health = {}  # every part's line again, for the newcomer
                self._detected = {}
                self.sensors.reset()
                self._model_sent = False
            self.state_loop.run(partial(self._publish_state, now, wall), stopping)
            if now >= next_description:
                next_description = now + DESCRIPTION_PERIOD_S
                self.state_loop.run(self._publish_description, stopping)
            if now >= next_health:
                next_health = now + HEALTH_PERIOD_S
                self.state_loop.run(partial(self._publish_health, wall), stopping)
            self.state_loop.run(partial(self._publish_detections, wall), stopping)
            self.state_loop.run(partial(self.sensors.publish, wall), stopping)

    def _publish_state(self, now: float, wall: float) -> None:
        if self.states.has_sinks():
            self.states.log(messages.joint_states(self.robot, self.joints, wall))
            self.published += 1
            self.rate.tick(now)
        if self.tf is not None and self.tf.has_sinks():
            self.tf.log(messages.frame_transforms(self.robot, self.joints, wall))

    def _publish_description(self) -> None:
        if self.description is not None and self.description.has_sinks():
            self.description.log({"data": self.joints.urdf})
        model, assets, urdf = self.model, self.assets, self.joints.urdf
        if model is None or assets is None or urdf is None or self._model_sent:
            return
        if model.has_sinks():
            model.log(model_scene(urdf, assets, time.time()))
            self._model_sent = True

    def _publish_health(self, wall: float) -> None:
        """Each part's line when it changed (all of them the first time)."""
        if not self.health.has_sinks():
            self._health = {}
            return
        buses = {n: h.as_dict() for n, h in self.robot.health().items()}
        sensors = {n: h.as_dict() for n, h in self.robot.sensor_health().items()}
        for line in messages.health_lines(buses, sensors):
            if self._health.get(line.part) != line:
                self._health[line.part] = line
                self.health.log(messages.log(line, self.name, wall))

    def _publish_detections(self, wall: float) -> None:
        """Each camera's detections when they change (and every second while they do not), while
        a detector of it runs and has looked once (never waiting for its first look here)."""
        for camera_name, channel in self.detections.items():
            camera = self.cameras[camera_name][0]
            detectors = [
                d for d in self._detectors(camera) if d.running and d.health().age_s is not None
            ]
            if not detectors or not channel.has_sinks():
                continue
            found = [
                thing
                for detector in detectors
                for thing in detector.found()
                if getattr(thing, "camera", camera_name) == camera_name
            ]
            last = self._detected.get(camera_name)
            if last is not None and last[1] == found and wall - last[0] < DETECTIONS_PERIOD_S:
                continue
            self._detected[camera_name] = (wall, found)
            channel.log(messages.image_annotations(found, wall))

    # -- cameras -----------------------------------------------------------------------------

    def _cameras(self) -> list[Camera]:
        from poppy_core.sensors import Camera

        return [s for s in self.robot.sensors if isinstance(s, Camera)]

    def _detectors(self, camera: Camera) -> list[Any]:
        from poppy_core.sensors.detector import FrameDetector

        return [
            s
            for s in self.robot.sensors
            if isinstance(s, FrameDetector) and any(c is camera for c in s.cameras)
        ]

    def _camera_loop(self, name: str, stopping: threading.Event) -> None:
        camera, channel = self.cameras[name]
        last = 0
        while not stopping.is_set():
            if not channel.has_sinks():  # a camera is opened for someone who watches
                stopping.wait(0.2)
                continue
            try:
                frame = camera.next_frame(after=last, timeout_s=1.0)
            except PoppyError:
                stopping.wait(0.2)  # a lost camera: its health says why, it comes back
                continue
            last = frame.number

            def publish(taken: Any = frame) -> None:
                jpeg = camera.encoded(taken, ".jpg")  # shared with the MJPEG viewers
                channel.log(messages.compressed_image(jpeg, name, time.time()))

            self.camera_loop.run(publish, stopping)
