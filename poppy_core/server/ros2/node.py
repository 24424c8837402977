"""``Ros2Node``: the robot as a ROS 2 node on rmw_zenoh's wire (``poppy serve --ros2``).

It declares on the server set's Zenoh session, under rmw_zenoh's keys (``wire``): publishers
``joint_states`` (every sync cycle), ``tf`` (with it), ``robot_description`` and ``tf_static``
(transient local: Zenoh advanced publishers with a cache of one sample, which rmw_zenoh's
transient-local subscriptions query), ``diagnostics`` (every second) and, while a camera runs,
``camera/image_raw/compressed``; subscriptions ``joint_trajectory`` and ``joint_command``;
services ``~/set_compliant``, ``~/stop`` and per primitive ``~/<primitive>/start`` and
``~/<primitive>/stop``; and the liveliness token of the node and of each of those entities.
Every sample and reply carries rmw_zenoh's attachment. Publications drop rather than wait.
"""

from __future__ import annotations

import logging
import re
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Any

from poppy_core import checks
from poppy_core import ros2_wire as wire
from poppy_core.errors import PoppyError
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.schedule import Periodic, RateMeter, TickGuard, Worker
from poppy_core.server.errors import ApiError
from poppy_core.server.ros2 import messages, rosout, types
from poppy_core.server.ros2.commands import CommandRefused, Commands
from poppy_core.server.ros2.joints import UrdfJoints
from poppy_core.server.ros2.refusal_log import Refusal, Refusals

if TYPE_CHECKING:
    import zenoh

    from poppy_core.server.service import RobotService

logger = logging.getLogger(__name__)

DIAGNOSTICS_PERIOD_S = 1.0
CAMERA_FRAME = "camera"
_PRIMITIVE = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


@dataclass
class _Publisher:
    name: str
    typ: types.RosType
    qos: wire.Qos
    publisher: Any = None
    gid: bytes = b""
    sequence: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def put(self, payload: bytes) -> None:
        with self.lock:
            self.sequence += 1
            extra = wire.attachment(self.sequence, time.time_ns(), self.gid)
            self.publisher.put(payload, attachment=extra)


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
        self.commands = Commands(self.robot, self.joints, self.state_rate_hz)
        self.rate = RateMeter()
        self.published = 0
        self.tokens: list[str] = []
        """The liveliness keys declared (node first)."""
        self._declared: list[Any] = []
        self._publishers: dict[str, _Publisher] = {}
        self._service_names: dict[str, str] = {}
        self._entity = 0
        self._zid = ""
        self._pool: ThreadPoolExecutor | None = None
        self._worker = Worker(f"ros2-{self.node}", self._publish_loop)
        self._camera_worker = Worker(f"ros2-camera-{self.node}", self._camera_loop)
        self.refusals = Refusals(logger)
        """Every command turned down, as ``Refusal`` events (``refusals.listen`` to publish
        them)."""
        self.state_loop = TickGuard(f"ros2-{self.node}")
        """The publish loop's failures (a raising tick is retried with backoff)."""
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

    def name_of(self, relative: str) -> str:
        """The fully qualified name of a topic or service of this node."""
        return wire.fully_qualified(self.namespace, self.node, relative)

    # -- declarations --------------------------------------------------------------------------

    def start(self) -> None:
        """Declare the node, its publishers, subscriptions and services; publish."""
        if self.running:
            return
        self._zid = str(self.session.info.zid())
        self._pool = ThreadPoolExecutor(2, thread_name_prefix=f"ros2-{self.node}")
        self._token(wire.NODE, 0)
        self._publisher("joint_states", types.JOINT_STATE, wire.DEFAULT_QOS)
        self._publisher("tf", types.TF_MESSAGE, wire.TF_QOS, topic="/tf")
        self._publisher(
            "diagnostics", types.DIAGNOSTIC_ARRAY, wire.DEFAULT_QOS, topic="/diagnostics"
        )
        self._publisher("rosout", rosout.LOG, rosout.ROSOUT_QOS, topic="/rosout")
        if self.joints.urdf is not None:
            self._publisher("robot_description", types.STRING, wire.LATCHED_QOS)
            self._publisher("tf_static", types.TF_MESSAGE, wire.LATCHED_QOS, topic="/tf_static")
        if self._cameras():
            self._publisher(
                "camera",
                types.COMPRESSED_IMAGE,
                wire.SENSOR_QOS,
                topic="camera/image_raw/compressed",
            )
        self._subscription("joint_trajectory", types.JOINT_TRAJECTORY, self._on_trajectory)
        self._subscription("joint_command", types.JOINT_STATE, self._on_command)
        self._service("~/set_compliant", types.SET_BOOL, self._set_compliant)
        self._service("~/stop", types.TRIGGER, self._stop_all)
        for primitive in self.service.primitives():
            if not _PRIMITIVE.fullmatch(primitive) or "__" in primitive:
                logger.info("ROS 2: primitive %r has no ROS name: no service", primitive)
                continue
            self._service(
                f"~/{primitive}/start", types.TRIGGER, self._primitive(primitive, "start")
            )
            self._service(f"~/{primitive}/stop", types.TRIGGER, self._primitive(primitive, "stop"))
        if self.joints.urdf is not None:
            self._publishers["robot_description"].put(
                types.serialize(messages.string(self.joints.urdf), types.STRING)
            )
            self._publishers["tf_static"].put(
                types.serialize(messages.tf_static(self.joints), types.TF_MESSAGE)
            )
        self._worker.start()
        if "camera" in self._publishers:
            self._camera_worker.start()

    def _next_id(self) -> int:
        self._entity += 1
        return self._entity

    def _token(
        self, kind: str, entity: int, topic: tuple[str, str, str, wire.Qos] | None = None
    ) -> str:
        key = wire.token_key(
            self.domain, self._zid, 0, entity, kind, self.namespace, self.node, topic=topic
        )
        self._declared.append(self.session.liveliness().declare_token(key))
        self.tokens.append(key)
        return key

    def _key(self, name: str, typ: types.RosType) -> str:
        return wire.data_key(self.domain, name, typ.dds, typ.hash)

    def _publisher(
        self, label: str, typename: str, qos: wire.Qos, *, topic: str | None = None
    ) -> None:
        import zenoh
        import zenoh.ext

        typ = types.ros_type(typename)
        name = self.name_of(topic or label)
        key = self._key(name, typ)
        drop = zenoh.CongestionControl.DROP
        publisher: Any
        if qos.durability == wire.TRANSIENT_LOCAL:
            publisher = zenoh.ext.declare_advanced_publisher(
                self.session,
                key,
                congestion_control=drop,
                cache=zenoh.ext.CacheConfig(qos.depth),
                publisher_detection=True,
            )
        else:
            publisher = self.session.declare_publisher(
                key,
                congestion_control=drop,
                express=True,
                reliability=zenoh.Reliability.BEST_EFFORT
                if qos.reliability == wire.BEST_EFFORT
                else zenoh.Reliability.RELIABLE,
            )
        self._declared.append(publisher)
        token = self._token(wire.PUBLISHER, self._next_id(), (name, typ.dds, typ.hash, qos))
        self._publishers[label] = _Publisher(name, typ, qos, publisher, wire.gid(token))

    def _subscription(self, topic: str, typename: str, handle: Any) -> None:
        typ = types.ros_type(typename)
        name = self.name_of(topic)

        def on_sample(sample: zenoh.Sample) -> None:
            try:
                message = types.deserialize(sample.payload.to_bytes(), typename)
            except Exception as exc:  # rosbags' SerdeError and its kin: a bad message
                self._refused(name, f"not a {typename} message ({exc})")
                return
            try:
                handle(message)
            except (CommandRefused, PoppyError, ApiError, ValueError) as exc:
                self._refused(name, str(exc))

        self._declared.append(self.session.declare_subscriber(self._key(name, typ), on_sample))
        self._token(wire.SUBSCRIPTION, self._next_id(), (name, typ.dds, typ.hash, wire.DEFAULT_QOS))

    def _service(self, relative: str, typename: str, handle: Any) -> None:
        typ = types.ros_type(typename)
        name = self.name_of(relative)
        key = self._key(name, typ)

        def on_query(query: zenoh.Query) -> None:
            pool = self._pool
            if pool is not None:  # off Zenoh's thread: a primitive's stop joins its thread
                pool.submit(self._answer, query, key, typename, handle)

        self._declared.append(self.session.declare_queryable(key, on_query, complete=True))
        self._service_names[key] = name
        self._token(wire.SERVICE, self._next_id(), (name, typ.dds, typ.hash, wire.SERVICE_QOS))

    def _answer(self, query: zenoh.Query, key: str, typename: str, handle: Any) -> None:
        try:
            self._reply(query, key, typename, handle)
        finally:
            query.drop()  # type: ignore[no-untyped-call]  # the client stops waiting

    def _reply(self, query: zenoh.Query, key: str, typename: str, handle: Any) -> None:
        try:
            asked = wire.read_attachment(query.attachment.to_bytes()) if query.attachment else None
            payload = query.payload.to_bytes() if query.payload is not None else b""
            request = types.deserialize(payload, f"{typename}_Request")
        except Exception as exc:  # a request that is not this service's
            logger.warning("ROS 2: %s: bad request: %s", key, exc)
            query.reply_err(f"bad request: {exc}".encode())
            return
        try:
            success, text = handle(request)
        except (PoppyError, ApiError, ValueError) as exc:
            success, text = False, str(exc)
        except Exception as exc:  # a reply still goes out: a client never waits in vain
            logger.exception("ROS 2: %s failed", key)
            success, text = False, f"failed: {exc}"
        if not success:
            self.refuse(Refusal(self._service_names.get(key, key), text, "service"))
        response = types.message(f"{typename}_Response", success=success, message=text)
        extra = wire.attachment(
            asked.sequence if asked else 0, time.time_ns(), asked.gid if asked else bytes(16)
        )
        query.reply(key, types.serialize(response, f"{typename}_Response"), attachment=extra)

    def _refused(self, topic: str, why: str) -> None:
        self.refuse(Refusal(topic, why, "topic"))

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

    def _publish_loop(self, stopping: threading.Event) -> None:
        schedule = Periodic(1.0 / self.state_rate_hz, time.monotonic())
        next_diagnostics = 0.0
        states = self._publishers["joint_states"]
        tf = self._publishers["tf"]
        while not stopping.is_set():
            wait = schedule.next_deadline - time.monotonic()
            if wait > 0 and stopping.wait(wait):
                return
            now = time.monotonic()
            schedule.advance(now)
            wall = time.time()
            self.state_loop.run(partial(self._publish_state, states, tf, now, wall), stopping)
            if now >= next_diagnostics:
                next_diagnostics = now + DIAGNOSTICS_PERIOD_S
                self.diagnostics_loop.run(partial(self._publish_diagnostics, wall), stopping)

    def _publish_state(self, states: _Publisher, tf: _Publisher, now: float, wall: float) -> None:
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
        self.commands.close()
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        tokens = [d for d in self._declared if type(d).__name__ == "LivelinessToken"]
        others = [d for d in self._declared if d not in tokens]
        for declared in [*reversed(tokens), *reversed(others)]:
            try:
                declared.undeclare()
            except Exception as exc:  # a session already closed
                logger.debug("undeclaring on Zenoh: %s", exc)
        self._declared = []
