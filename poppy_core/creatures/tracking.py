"""Ergo Jr and markers: ``tracking_feedback`` (LEDs say one is seen), ``marker_follow`` (the head
turns to keep one in the middle of its camera's view); ``FollowInView``, what ``marker_follow``
and ``face_tracking`` share.

``tracking_feedback`` is poppy-ergo-jr's behaviour of that name: the tip motors' LEDs are green
while a marker was seen in any of the last six updates, off otherwise. ``marker_follow`` is the
"head follows a marker" the Poppy lessons show, built on the arm's kinematic chain: the camera
looks along the tip's -z (see ``sim.looks.CAMERAS``), so the marker's pixel gives a direction in
the chain's base frame, and a damped least-squares step of the chosen joints turns the camera's
axis towards it. It works the same on the real robot and in MuJoCo (``SimCamera``).
"""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from poppy_core.errors import PoppyError, SensorError, UnknownCardError
from poppy_core.motion import LoopPrimitive
from poppy_core.motion.cartesian import RobotChain

if TYPE_CHECKING:
    from poppy_core.robot import Robot

logger = logging.getLogger(__name__)

FEEDBACK_WINDOW = 6
"""Updates a sighting keeps the LEDs lit (poppy-ergo-jr's ``TrackingFeedback`` queue length)."""
FOLLOW_HZ = 5.0
"""The marker detector's default rate: acting faster would apply the same sighting twice."""
DEAD_ZONE_DEG = 1.5
SETTLE_S = 0.05
"""After a move, frames taken sooner than this after its end are not acted on."""
MAX_STEP_DEG = 12.0
PROBE_DEG = 0.5
DAMPING = 0.05
ERGO_JR_FOVY_DEG = 41.4
"""Vertical field of view when the camera has no calibration (Raspberry Pi camera v1)."""
FOLLOWING_MOTORS = ("m1", "m5", "m6")
"""Base yaw and the two head pitches: enough to aim, without folding the arm."""


def _detector(robot: Robot, detector: Any) -> Any:
    return robot.sensor(detector) if isinstance(detector, str) else detector


def _wanted_ids(detector: Any, marker: str | int | None) -> set[int] | None:
    """The marker ids ``marker`` names (a card name or an id); None: any marker."""
    if marker is None or marker == "":
        return None
    if isinstance(marker, int):
        return {marker}
    text = str(marker).strip()
    if text.lstrip("-").isdigit():
        return {int(text)}
    cards: dict[str, list[int]] = getattr(detector, "card_ids", {})
    if text not in cards:
        known = list(cards)
        raise UnknownCardError(
            f"no card {text!r} (cards: {', '.join(known) or 'none'}; or give a marker id)",
            name=text,
            known=known,
        )
    return set(cards[text])


class TrackingFeedback(LoopPrimitive):
    """The tip motors' LEDs show whether the marker detector sees a marker.

    Args:
        robot: a robot with a marker detector.
        freq: updates per second.
        detector: the detector, or its sensor name.
        color: the LED colour while a marker is seen.
        motors: the motors whose LEDs light.
    """

    properties: ClassVar[Sequence[str]] = ("color", "update_freq")

    def __init__(
        self,
        robot: Robot,
        freq: float = 10.0,
        detector: Any = "marker_detector",
        color: str = "green",
        motors: Sequence[str] = ("m4", "m5", "m6"),
    ) -> None:
        super().__init__(robot, freq)
        self.detector = _detector(robot, detector)
        self.color = color
        self.led_motors = [robot.motor(name).name for name in motors]
        self._sightings: deque[bool] = deque(maxlen=FEEDBACK_WINDOW)
        self._lit: bool | None = None
        self._warned = False

    @property
    def tracking(self) -> bool:
        """Whether a marker was seen in the last few updates."""
        return any(self._sightings)

    def setup(self) -> None:
        self._sightings.clear()
        self._lit = None
        self._warned = False

    def update(self) -> None:
        try:
            seen = bool(self.detector.markers)
        except SensorError as exc:
            if not self._warned:
                logger.warning("tracking_feedback: %s", exc)
                self._warned = True
            seen = False
        self._sightings.append(seen)
        if self.tracking != self._lit:
            self._lit = self.tracking
            for name in self.led_motors:
                self.get_mockup_motor(name).led = self.color if self._lit else "off"

    def teardown(self) -> None:
        for name in self.led_motors:
            self.get_mockup_motor(name).led = "off"


class FollowInView(LoopPrimitive):
    """Turn the chain so that its camera keeps something its detector sees in the middle of the
    view (``marker_follow``, ``face_tracking``); subclasses choose what (``pick``).

    Args:
        robot: a robot with the chain, a camera at the chain's tip and a detector.
        chain: the chain carrying the camera (looking along the tip's -z).
        detector: the detector (its ``cameras`` and ``detect(camera)``), or its sensor name.
        freq: updates per second (each acts on a frame taken after the last move ended).
        gain: the share of the seen error corrected per update (0..1].
        motors: the chain's joints that move.
    """

    properties: ClassVar[Sequence[str]] = ("gain", "update_freq")

    def __init__(
        self,
        robot: Robot,
        chain: str = "chain",
        detector: Any = "marker_detector",
        freq: float = FOLLOW_HZ,
        gain: float = 0.7,
        motors: Sequence[str] = FOLLOWING_MOTORS,
    ) -> None:
        super().__init__(robot, freq)
        self.chain_name = chain
        self.detector = _detector(robot, detector)
        self.gain = gain
        self.moving = list(motors)
        self._last_sighting: tuple[Any, ...] | None = None
        self._still_from = 0.0
        self._axes: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def pick(self, found: list[Any]) -> Any | None:
        """The one of ``found`` (things seen in one frame, each with ``center`` in pixels and
        ``camera``) to follow, or None."""
        raise NotImplementedError

    @property
    def gain(self) -> float:
        """The share of the seen error corrected per update (0..1]."""
        return self._gain

    @gain.setter
    def gain(self, value: float) -> None:
        gain = float(value)
        if not 0.0 < gain <= 1.0:
            raise PoppyError(f"gain must be in (0, 1], not {value!r}")
        self._gain = gain

    def _chain(self) -> RobotChain:
        chain = self.real_robot.extensions.get(self.chain_name)
        if not isinstance(chain, RobotChain):
            raise PoppyError(f"the robot has no chain {self.chain_name!r} to aim its camera")
        return chain

    def camera_axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The camera's (right, down, look) unit vectors in the tip's frame.

        It looks along the tip's -z; its image's "up" is the world's up at the zero pose.
        """
        if self._axes is None:
            model = self._chain().model
            zero = model.forward({name: 0.0 for name in model.names})[:3, :3]
            look = np.array([0.0, 0.0, -1.0])
            up = zero.T @ np.array([0.0, 0.0, 1.0])
            up = up - look * float(up @ look)
            up /= np.linalg.norm(up)
            right = np.cross(look, up)
            self._axes = (right, -up, look)
        return self._axes

    def setup(self) -> None:
        chain = self._chain()
        unknown = [name for name in self.moving if name not in chain.model.names]
        if unknown:
            raise PoppyError(
                f"{self.name}: {', '.join(unknown)} not in chain "
                f"{self.chain_name!r} "
                f"(its joints: {', '.join(chain.model.names)})"
            )
        self.robot.compliant = False
        self._last_sighting = None
        self._still_from = 0.0

    def _sighting(self) -> Any | None:
        """What is followed in the newest frame taken after the last move ended, if any."""
        camera = self.detector.cameras[0]
        if camera.latest().time_s < self._still_from:
            return None  # taken while the head was still turning: it would overshoot
        return self.pick(list(self.detector.detect(camera)))

    def _pixel_ray(self, seen: Any) -> np.ndarray:
        """The direction of what is seen in the camera's (right, down, look) axes."""
        camera = next((c for c in self.detector.cameras if c.name == seen.camera), None)
        camera = camera or self.detector.cameras[0]
        calibration = getattr(camera, "calibration", None)
        if calibration is not None:
            matrix = np.asarray(calibration.camera_matrix, dtype=float)
            fx, fy, cx, cy = matrix[0, 0], matrix[1, 1], matrix[0, 2], matrix[1, 2]
        else:
            width, height = camera.resolution
            fy = fx = (height / 2.0) / math.tan(math.radians(ERGO_JR_FOVY_DEG) / 2.0)
            cx, cy = width / 2.0, height / 2.0
        u, v = seen.center
        ray = np.array([(u - cx) / fx, (v - cy) / fy, 1.0])
        unit: np.ndarray = ray / np.linalg.norm(ray)
        return unit

    def aim_step(self, present: dict[str, float], ray_camera: np.ndarray) -> dict[str, float]:
        """Goals for the moving joints that turn the camera towards ``ray_camera``."""
        model = self._chain().model
        right, down, look = self.camera_axes()
        to_tip = np.column_stack([right, down, look])

        def looking(angles: dict[str, float]) -> np.ndarray:
            rotation = model.forward(angles, present)[:3, :3]
            out: np.ndarray = rotation @ look
            return out

        rotation = model.forward(present, present)[:3, :3]
        wanted = rotation @ (to_tip @ ray_camera)
        now = looking(present)
        error = wanted - now
        columns = []
        for name in self.moving:
            nudged = dict(present, **{name: present[name] + PROBE_DEG})
            columns.append((looking(nudged) - now) / PROBE_DEG)
        jacobian = np.column_stack(columns)
        square = jacobian @ jacobian.T + DAMPING**2 * np.eye(3)
        step = self.gain * (jacobian.T @ np.linalg.solve(square, error))
        step = np.clip(step, -MAX_STEP_DEG, MAX_STEP_DEG)
        limits = {j.name: j.limits_deg for j in model.joints}
        goals = {}
        for name, delta in zip(self.moving, step, strict=True):
            low, high = limits.get(name) or (-180.0, 180.0)
            goals[name] = float(np.clip(present[name] + delta, low, high))
        return goals

    def update(self) -> None:
        try:
            seen = self._sighting()
        except SensorError as exc:
            logger.debug("%s: %s", self.name, exc)
            return
        if seen is None:
            return
        key = (seen.camera, *seen.center)
        if key == self._last_sighting:  # no new frame since the last step
            return
        self._last_sighting = key
        ray = self._pixel_ray(seen)
        if math.degrees(math.acos(min(1.0, float(ray[2])))) < DEAD_ZONE_DEG:
            return
        chain = self._chain()
        present = {m.name: m.present_position for m in chain.motors}
        goals = self.aim_step(present, ray)
        duration_s = 0.8 * self.period_s
        self.robot.goto_position(goals, duration_s, control="minjerk")
        camera = self.detector.cameras[0]
        self._still_from = camera.clock_s() + duration_s + SETTLE_S


class MarkerFollow(FollowInView):
    """Turn the chain so that its camera keeps a marker in the middle of the view.

    Args:
        robot: a robot with the chain, a camera at the chain's tip and a marker detector.
        chain: the chain carrying the camera (looking along the tip's -z).
        detector: the detector, or its sensor name.
        marker: the marker to follow: an id or a card name; None follows the largest one seen.
        freq: updates per second (each acts on a frame taken after the last move ended).
        gain: the share of the seen error corrected per update (0..1].
        motors: the chain's joints that move.
    """

    properties: ClassVar[Sequence[str]] = ("marker", "gain", "update_freq")

    def __init__(
        self,
        robot: Robot,
        chain: str = "chain",
        detector: Any = "marker_detector",
        marker: str | int | None = None,
        freq: float = FOLLOW_HZ,
        gain: float = 0.7,
        motors: Sequence[str] = FOLLOWING_MOTORS,
    ) -> None:
        super().__init__(robot, chain, detector, freq, gain, motors)
        self.marker = marker

    @property
    def marker(self) -> str | int | None:
        """The marker followed (an id or a card name; None: the largest seen)."""
        return self._marker

    @marker.setter
    def marker(self, value: str | int | None) -> None:
        self._wanted = _wanted_ids(self.detector, value)
        self._marker = value

    def pick(self, found: list[Any]) -> Any | None:
        markers = [m for m in found if self._wanted is None or m.id in self._wanted]
        if not markers:
            return None

        def area(m: Any) -> float:
            xs, ys = zip(*m.corners, strict=True)
            return float((max(xs) - min(xs)) * (max(ys) - min(ys)))

        return max(markers, key=area)
