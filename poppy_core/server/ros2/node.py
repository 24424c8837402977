"""``Ros2Node``: the robot as a ROS 2 node on rmw_zenoh's wire (``poppy serve --ros2``).

It declares on the server set's Zenoh session, under rmw_zenoh's keys (``wire``): publishers
``joint_states`` (every sync cycle), ``tf`` (with it), ``robot_description`` and ``tf_static``
(transient local: Zenoh advanced publishers with a cache of one sample, which rmw_zenoh's
transient-local subscriptions query), ``diagnostics`` (every second) and, while a camera runs,
``camera/image_raw/compressed``, ``<imu>/data`` for each IMU (sensor_msgs/Imu, with the
state), the tracked skeletons on ``tf`` (a frame per user and joint, under the sensor's);
subscriptions ``joint_trajectory`` and ``joint_command``; services
``~/set_compliant``, ``~/stop`` and per primitive ``~/<primitive>/start`` and
``~/<primitive>/stop``; and the liveliness token of the node and of each of those entities.
The entities are declared by ``entities.Entities``; the commands are the service's operations
(``commands.Commands``). Every sample and reply carries rmw_zenoh's attachment. Publications
drop rather than wait.
"""

from __future__ import annotations

import logging
import re
import threading
import time
from functools import partial
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core import ros2_wire as wire
from poppy_core.errors import PoppyError
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.schedule import RateMeter, TickGuard, Worker
from poppy_core.server.ros2 import messages, rosout, types
from poppy_core.server.ros2.commands import Commands
from poppy_core.server.ros2.entities import Entities, Publisher
from poppy_core.server.ros2.joints import UrdfJoints
from poppy_core.server.ros2.refusal_log import Refusal, Refusals

if TYPE_CHECKING:
    import zenoh

    from poppy_core.server.service import RobotService

logger = logging.getLogger(__name__)

DIAGNOSTICS_PERIOD_S = 1.0
CAMERA_FRAME = "camera"
_PRIMITIVE = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


class Ros2Node:
    """The robot of ``service`` as a ROS 2 node on ``session``.

    Args:
        service: the robot service shared with the other servers.
        session: the server set's Zenoh session.
        settings: domain, namespace and node name.
        name: the robot's name (the node's, made a ROS name, when the settings give none).
        state_rate_hz: ``joint_states`` per second (the sync loop's rate).
    """

    def __init__(
        self,
        service: RobotService,
        session: zenoh.Session,
        settings: Ros2Settings,
        name: str,
        *,
        state_rate_hz: float = 50.0,
    ) -> None:
        types.typestore()  # a missing rosbags (the ros2 extra) is one line, before serving
        self.service = service
        self.robot = service.robot
        self.session = session
        self.settings = settings
        self.domain = settings.domain
        self.namespace = settings.namespace
        self.node = settings.node or wire.node_name_from(name)
        self.state_rate_hz = checks.rate(state_rate_hz, "state_rate_hz")
        self.joints = UrdfJoints(self.robot)
        self.commands = Commands(service, self.joints)
        self.rate = RateMeter()
        self.published = 0
        self.entities = Entities(session, self.domain, self.namespace, self.node, self.refuse)
        self._publishers = self.entities.publishers
        self._worker = Worker.periodic(f"ros2-{self.node}", self.state_rate_hz, self._tick)
        self._camera_worker = Worker(f"ros2-camera-{self.node}", self._camera_loop)
        self.refusals = Refusals(logger)
        """Every command turned down, as ``Refusal`` events (``refusals.listen`` to publish
        them)."""
        assert self._worker.ticker is not None
        self.state_loop = self._worker.ticker.guard
        """The publish loop's failures (a raising tick is retried with backoff)."""
        self._next_diagnostics = 0.0
        self.diagnostics_loop = TickGuard(f"ros2-diagnostics-{self.node}")
        self.camera_loop = TickGuard(f"ros2-camera-{self.node}")
        self._rosout = rosout.RosoutRefusals(self._publish_rosout)
        self.refusals.listen(self._rosout.publish)

    @property
    def url(self) -> str:
        """``ros2:/NAMESPACE/NODE`` (for the server list)."""
        return f"ros2:{wire.fully_qualified(self.namespace, self.node, '~')}"

    @property
    def port(self) -> None:
        """No port of its own."""
        return None

    @property
    def running(self) -> bool:
        """True while ``joint_states`` is published."""
        return self._worker.running

    @property
    def tokens(self) -> list[str]:
        """The liveliness keys declared (node first)."""
        return self.entities.tokens

    def name_of(self, relative: str) -> str:
        """The fully qualified name of a topic or service of this node."""
        return self.entities.name_of(relative)

    # -- declarations --------------------------------------------------------------------------

    def start(self) -> None:
        """Declare the node, its publishers, subscriptions and services; publish."""
        if self.running:
            return
        entities = self.entities
        entities.open()
        entities.publisher("joint_states", types.JOINT_STATE, wire.DEFAULT_QOS)
        entities.publisher("tf", types.TF_MESSAGE, wire.TF_QOS, topic="/tf")
        entities.publisher(
            "diagnostics", types.DIAGNOSTIC_ARRAY, wire.DEFAULT_QOS, topic="/diagnostics"
        )
        entities.publisher("rosout", rosout.LOG, rosout.ROSOUT_QOS, topic="/rosout")
        if self.joints.urdf is not None:
            entities.publisher("robot_description", types.STRING, wire.LATCHED_QOS)
            entities.publisher("tf_static", types.TF_MESSAGE, wire.LATCHED_QOS, topic="/tf_static")
        if self._cameras():
            entities.publisher(
                "camera",
                types.COMPRESSED_IMAGE,
                wire.SENSOR_QOS,
                topic="camera/image_raw/compressed",
            )
        for imu in self._imus():
            entities.publisher(
                f"imu:{imu.name}", types.IMU, wire.SENSOR_QOS, topic=f"{imu.name}/data"
            )
            imu.start()  # a small device read at its own rate (a camera is never opened here)
        for sensor in self._skeleton_sensors():
            if sensor.kind == "KinectSensor":
                sensor.start()  # a network read; a camera pose waits for its first reader
        entities.subscription("joint_trajectory", types.JOINT_TRAJECTORY, self._on_trajectory)
        entities.subscription("joint_command", types.JOINT_STATE, self._on_command)
        entities.service("~/set_compliant", types.SET_BOOL, self._set_compliant)
        entities.service("~/stop", types.TRIGGER, self._stop_all)
        for primitive in self.service.primitives():
            if not _PRIMITIVE.fullmatch(primitive) or "__" in primitive:
                logger.info("ROS 2: primitive %r has no ROS name: no service", primitive)
                continue
            entities.service(
                f"~/{primitive}/start", types.TRIGGER, self._primitive(primitive, "start")
            )
            entities.service(
                f"~/{primitive}/stop", types.TRIGGER, self._primitive(primitive, "stop")
            )
        if self.joints.urdf is not None:
            self._publishers["robot_description"].put(
                types.serialize(messages.string(self.joints.urdf), types.STRING)
            )
            self._publishers["tf_static"].put(
                types.serialize(messages.tf_static(self.joints), types.TF_MESSAGE)
            )
        self._next_diagnostics = 0.0
        self._worker.start()
        if "camera" in self._publishers:
            self._camera_worker.start()

    def refuse(self, refusal: Refusal) -> None:
        """The one place a refusal of the node goes: counted, logged, handed to listeners."""
        if refusal.kind == "topic":
            self.commands.refused += 1
        self.refusals.report(refusal)

    def _publish_rosout(self, text: str, function: str) -> None:
        publisher = self._publishers.get("rosout")
        if publisher is not None:
            log = rosout.log_message(self.name_of("~"), rosout.WARN, text, function)
            publisher.put(types.serialize(log, rosout.LOG))

    # -- commands and services -----------------------------------------------------------------

    def _on_trajectory(self, message: Any) -> None:
        self.commands.follow(message)

    def _on_command(self, message: Any) -> None:
        self.commands.command(list(message.name), list(message.position))

    def _set_compliant(self, request: Any) -> tuple[bool, str]:
        compliant = bool(request.data)
        if compliant:
            self.commands.stop()
        self.service.set_compliant(compliant)
        return True, "compliant" if compliant else "stiff"

    def _stop_all(self, request: Any) -> tuple[bool, str]:
        self.commands.stop()
        stopped = []
        for primitive in self.service.running_primitives():
            self.service.control_primitive(primitive, "stop")
            stopped.append(primitive)
        return True, "stopped " + (", ".join(stopped) if stopped else "the trajectory")

    def _primitive(self, primitive: str, action: str) -> Any:
        def run(request: Any) -> tuple[bool, str]:
            if action == "start":
                self.commands.stop()
            self.service.control_primitive(primitive, action)
            return True, f"{primitive}: {action}"

        return run

    # -- publications ------------------------------------------------------------------------

    def _tick(self, now: float) -> None:
        wall = time.time()
        if now >= self._next_diagnostics:  # guarded apart: a failing state still has its health
            self._next_diagnostics = now + DIAGNOSTICS_PERIOD_S
            self.diagnostics_loop.run(
                partial(self._publish_diagnostics, wall), self._worker.stopping
            )
        self._publish_state(self._publishers["joint_states"], self._publishers["tf"], now, wall)
        for imu in self._imus():
            if imu.health().age_s is not None:  # a value read: the properties do not wait
                message = messages.imu(imu, imu.name, wall)
                self._publishers[f"imu:{imu.name}"].put(types.serialize(message, types.IMU))
        for sensor in self._skeleton_sensors():
            if sensor.running and sensor.health().age_s is not None:  # reading does not start it
                skeletons = sensor.tracked_skeleton
                if skeletons:
                    message = messages.skeletons_tf(skeletons, sensor.name, wall)
                    self._publishers["tf"].put(types.serialize(message, types.TF_MESSAGE))

    def _publish_state(self, states: Publisher, tf: Publisher, now: float, wall: float) -> None:
        states.put(
            types.serialize(messages.joint_state(self.robot, self.joints, wall), types.JOINT_STATE)
        )
        self.published += 1
        self.rate.tick(now)
        if self.joints.description is not None:
            tf.put(
                types.serialize(
                    messages.tf_message(self.robot, self.joints, wall), types.TF_MESSAGE
                )
            )

    def _publish_diagnostics(self, wall: float) -> None:
        self._publishers["diagnostics"].put(
            types.serialize(self.diagnostics(wall), types.DIAGNOSTIC_ARRAY)
        )

    def diagnostics(self, now: float | None = None) -> Any:
        """The buses' and sensors' health as a DiagnosticArray."""
        sensors = {
            name: "ok" if health.ok else (health.last_error or "not ok")
            for name, health in self.robot.sensor_health().items()
        }
        array = messages.diagnostics(self.node, self.service.health(), sensors, now)
        array.status.append(rosout.commands_status(self.refusals, self.node))
        return array

    def _cameras(self) -> list[Any]:
        from poppy_core.sensors import Camera

        return [s for s in self.robot.sensors if isinstance(s, Camera)]

    def _skeleton_sensors(self) -> list[Any]:
        from poppy_core.sensors import skeleton_sensors

        return skeleton_sensors(self.robot.sensors)

    def _imus(self) -> list[Any]:
        from poppy_core.sensors import Imu

        return [s for s in self.robot.sensors if isinstance(s, Imu)]

    def _camera_loop(self, stopping: threading.Event) -> None:
        camera = self._cameras()[0]
        publisher = self._publishers["camera"]
        last = 0
        while not stopping.is_set():
            if not camera.running:  # published while a camera is open, never opened here
                stopping.wait(0.5)
                continue
            try:
                frame = camera.next_frame(after=last, timeout_s=1.0, start=False)
            except PoppyError:
                continue
            last = frame.number

            def publish(taken: Any = frame) -> None:
                jpeg = camera.encoded(taken, ".jpg")  # shared with the MJPEG viewers
                message = messages.compressed_image(jpeg, CAMERA_FRAME, time.time())
                publisher.put(types.serialize(message, types.COMPRESSED_IMAGE))

            self.camera_loop.run(publish, stopping)

    def stop(self) -> None:
        """Stop publishing and following, then undeclare everything (tokens first)."""
        self._worker.close()
        self._camera_worker.close()
        self.commands.stop()
        self.entities.close()
