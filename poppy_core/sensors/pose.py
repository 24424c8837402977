"""``PoseSkeleton``: a person's skeleton from any camera, with the Kinect's joint names (MediaPipe).

Config: ``{"type": "PoseSkeleton", "camera": "camera"}`` (a webcam, the robot's camera, the
simulated one). MediaPipe Pose finds one person's 33 landmarks in the camera's frames
(``pose_worker.py``, a child process in its own venv: ``pose_venv``); they become pypot's
``KinectSensor`` skeleton: ``tracked_skeleton`` is ``{0: Skeleton}`` while someone is seen,
with the 20 joints ``hip_center`` ... ``foot_right``, each with

- ``position``: metres, in the Kinect's skeleton-space axes (x to the camera's left, y up, z
  away from the camera), from the centre of the hips (MediaPipe's world landmarks, which give
  no distance to the camera);
- ``pixel_coordinate``: where the joint is in the camera's frame (pixels);
- ``orientation``: the shortest rotation taking y onto the bone that ends at the joint (as the
  Kinect SDK's bone orientations point y along the bone; the twist about the bone is unknown).

Landmarks to joints: shoulders, elbows, wrists, hips, knees, ankles are MediaPipe's; a hand is
the middle of its index and little finger knuckles, a foot its toe landmark, the head the middle
of the ears, ``shoulder_center`` and ``hip_center`` the middles of the pairs, ``spine`` a quarter
of the way from the hips' centre to the shoulders'. Left and right are the person's.
"""

from __future__ import annotations

import json
import logging
import os
import select
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from poppy_core.errors import SensorError
from poppy_core.sensors.base import SensorLost
from poppy_core.sensors.camera import Camera
from poppy_core.sensors.detector import FrameDetector
from poppy_core.sensors.kinect import (
    JOINTS,
    Point2D,
    Point3D,
    Quaternion,
    Skeleton,
    SkeletonJoint,
)

logger = logging.getLogger(__name__)

DEFAULT_POSE_FREQ_HZ = 10.0
READY_TIMEOUT_S = 120.0
"""How long the worker may take to import MediaPipe and load its model (a busy machine)."""
ANSWER_TIMEOUT_S = 30.0
WORKER = Path(__file__).with_name("pose_worker.py")

_L_SHOULDER, _R_SHOULDER, _L_ELBOW, _R_ELBOW, _L_WRIST, _R_WRIST = 11, 12, 13, 14, 15, 16
_L_HIP, _R_HIP, _L_KNEE, _R_KNEE, _L_ANKLE, _R_ANKLE = 23, 24, 25, 26, 27, 28
_HIPS = {_L_HIP: 0.5, _R_HIP: 0.5}
_SHOULDERS = {_L_SHOULDER: 0.5, _R_SHOULDER: 0.5}
JOINT_LANDMARKS: dict[str, dict[int, float]] = {
    "hip_center": _HIPS,
    "spine": {k: 0.75 * v for k, v in _HIPS.items()} | {k: 0.25 * v for k, v in _SHOULDERS.items()},
    "shoulder_center": _SHOULDERS,
    "head": {7: 0.5, 8: 0.5},
    "shoulder_left": {_L_SHOULDER: 1.0},
    "elbow_left": {_L_ELBOW: 1.0},
    "wrist_left": {_L_WRIST: 1.0},
    "hand_left": {17: 0.5, 19: 0.5},
    "shoulder_right": {_R_SHOULDER: 1.0},
    "elbow_right": {_R_ELBOW: 1.0},
    "wrist_right": {_R_WRIST: 1.0},
    "hand_right": {18: 0.5, 20: 0.5},
    "hip_left": {_L_HIP: 1.0},
    "knee_left": {_L_KNEE: 1.0},
    "ankle_left": {_L_ANKLE: 1.0},
    "foot_left": {31: 1.0},
    "hip_right": {_R_HIP: 1.0},
    "knee_right": {_R_KNEE: 1.0},
    "ankle_right": {_R_ANKLE: 1.0},
    "foot_right": {32: 1.0},
}
"""Each Kinect joint as a weighted mean of MediaPipe Pose's landmarks (their indices)."""
PARENTS: dict[str, str] = {
    "spine": "hip_center",
    "shoulder_center": "spine",
    "head": "shoulder_center",
    **{f"shoulder_{s}": "shoulder_center" for s in ("left", "right")},
    **{f"elbow_{s}": f"shoulder_{s}" for s in ("left", "right")},
    **{f"wrist_{s}": f"elbow_{s}" for s in ("left", "right")},
    **{f"hand_{s}": f"wrist_{s}" for s in ("left", "right")},
    **{f"hip_{s}": "hip_center" for s in ("left", "right")},
    **{f"knee_{s}": f"hip_{s}" for s in ("left", "right")},
    **{f"ankle_{s}": f"knee_{s}" for s in ("left", "right")},
    **{f"foot_{s}": f"ankle_{s}" for s in ("left", "right")},
}
"""The bone ending at each joint starts at its parent (``hip_center``'s bone goes to ``spine``)."""
_TO_KINECT = np.array([-1.0, -1.0, 1.0])
"""MediaPipe's world axes (x right and y down in the image) to the Kinect's (x left, y up)."""


def _bone_rotation(direction: np.ndarray) -> Quaternion:
    """The shortest rotation (x, y, z, w) taking +y onto ``direction``."""
    norm = float(np.linalg.norm(direction))
    if norm < 1e-9:
        return Quaternion(0.0, 0.0, 0.0, 1.0)
    d = direction / norm
    y = np.array([0.0, 1.0, 0.0])
    w = 1.0 + float(d @ y)
    if w < 1e-9:  # pointing down: half a turn about x
        return Quaternion(1.0, 0.0, 0.0, 0.0)
    axis = np.cross(y, d)
    q = np.array([*axis, w]) / np.linalg.norm([*axis, w])
    return Quaternion(*(float(v) for v in q))


def _mix(values: np.ndarray, weights: dict[int, float]) -> np.ndarray:
    """The weighted mean of some rows of ``values``."""
    mixed: np.ndarray = np.sum([values[i] * w for i, w in weights.items()], axis=0)
    return mixed


def skeleton_from_landmarks(
    landmarks: Sequence[Sequence[float]],
    world: Sequence[Sequence[float]],
    size: tuple[int, int],
    timestamp: Any = None,
    user_id: Any = 0,
) -> Skeleton:
    """The Kinect-named skeleton of MediaPipe's 33 landmarks (``size``: the frame's width, height).

    Raises:
        ValueError: not 33 landmarks of 3 or more numbers each.
    """
    image = np.asarray(landmarks, dtype=float)
    metres = np.asarray(world, dtype=float)
    if image.shape[0] != 33 or metres.shape[0] != 33 or image.shape[1] < 2 or metres.shape[1] < 3:
        raise ValueError(f"33 landmarks expected, got {image.shape} and {metres.shape}")
    width, height = size
    pixels = image[:, :2] * np.array([width, height])
    positions = metres[:, :3] * _TO_KINECT
    at = {name: _mix(positions, JOINT_LANDMARKS[name]) for name in JOINTS}
    out = []
    for name in JOINTS:
        parent = PARENTS.get(name)
        bone = at["spine"] - at["hip_center"] if parent is None else at[name] - at[parent]
        px = _mix(pixels, JOINT_LANDMARKS[name])
        out.append(
            SkeletonJoint(
                Point3D(*(float(v) for v in at[name])),
                _bone_rotation(bone),
                Point2D(float(px[0]), float(px[1])),
            )
        )
    return Skeleton(timestamp, user_id, *out)


def pose_python(python: str | None = None) -> Path | None:
    """The interpreter that runs MediaPipe Pose: ``python`` (a config's), else the pose venv's,
    else this one if it imports MediaPipe's pose; None when there is none."""
    from poppy_core.sensors.pose_venv import venv_python  # its ``-m`` runs alone

    if python:
        return Path(python)
    made = venv_python()
    if made.is_file():
        return made
    from importlib.util import find_spec

    try:
        here = find_spec("mediapipe.python.solutions.pose") is not None
    except ModuleNotFoundError:
        here = False
    return Path(sys.executable) if here else None


class PoseWorker:
    """The MediaPipe Pose child process: ``estimate(rgb)`` -> landmarks (or None).

    Args:
        python: the interpreter of a venv with MediaPipe 0.10.21.
        static: every frame on its own (still images) rather than tracking between frames.

    Raises:
        SensorLost: the worker does not start or stopped answering (the message says why).
    """

    def __init__(self, python: Path, *, static: bool = False) -> None:
        self.python = python
        args = [str(python), str(WORKER), *(["--static"] if static else [])]
        try:
            self._process = subprocess.Popen(
                args,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,  # MediaPipe's own logging; failures come on stdout
                bufsize=0,
                env=dict(os.environ, GLOG_minloglevel="2", TF_CPP_MIN_LOG_LEVEL="2"),
            )
        except OSError as exc:
            raise SensorLost(f"cannot run {python}: {exc}") from None
        self._buffer = b""
        try:
            first = self._answer(READY_TIMEOUT_S)
        except SensorLost:
            self.close()
            raise
        if "ready" not in first:
            self.close()
            raise SensorLost(f"the pose worker did not start: {first.get('error', first)}")
        self.version = str(first["ready"])

    def _answer(self, timeout_s: float) -> dict[str, Any]:
        stdout = self._process.stdout
        assert stdout is not None
        while b"\n" not in self._buffer:
            ready, _, _ = select.select([stdout], [], [], timeout_s)
            if not ready:
                raise SensorLost(f"the pose worker gave no answer in {timeout_s:g} s")
            chunk = os.read(stdout.fileno(), 1 << 16)
            if not chunk:
                code = self._process.poll()
                raise SensorLost(f"the pose worker exited (code {code})")
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        try:
            answer = json.loads(line)
        except ValueError:
            raise SensorLost(f"the pose worker said {line[:80]!r}") from None
        if not isinstance(answer, dict):
            raise SensorLost(f"the pose worker said {line[:80]!r}")
        return answer

    def estimate(self, rgb: np.ndarray) -> dict[str, Any] | None:
        """MediaPipe's answer for one RGB frame: ``{"landmarks", "world"}``, None: nobody."""
        stdin = self._process.stdin
        assert stdin is not None
        height, width = rgb.shape[:2]
        header = json.dumps({"width": width, "height": height}).encode() + b"\n"
        try:
            stdin.write(header + np.ascontiguousarray(rgb, dtype=np.uint8).tobytes())
        except (BrokenPipeError, OSError) as exc:
            raise SensorLost(f"the pose worker stopped: {exc}") from None
        answer = self._answer(ANSWER_TIMEOUT_S)
        if "error" in answer:
            raise SensorError(f"pose worker: {answer['error']}")
        return None if answer.get("landmarks") is None else answer

    def close(self) -> None:
        """End the child process."""
        process = self._process
        for stream in (process.stdin, process.stdout):
            if stream is not None:
                stream.close()
        try:
            process.wait(2.0)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


class PoseSkeleton(FrameDetector[Skeleton]):
    """A person's skeleton in a camera's frames, as a Kinect's (``tracked_skeleton``).

    Args:
        name: the sensor's name.
        camera: the camera to look through.
        freq: estimations per second (about 20 ms of a core each at 640x480 while tracking).
        python: the interpreter of a venv with MediaPipe 0.10.21 (None: ``pose_python()``).
        static: estimate each frame on its own (no tracking between frames: still images).
    """

    registers: ClassVar[tuple[str, ...]] = ("tracked_skeleton",)
    what: ClassVar[str] = "skeletons"

    def __init__(
        self,
        name: str,
        camera: Camera,
        freq: float = DEFAULT_POSE_FREQ_HZ,
        *,
        python: str | None = None,
        static: bool = False,
    ) -> None:
        super().__init__(name, [camera], freq)
        self.static = static
        self._worker: PoseWorker | None = None
        self._python = pose_python(python)
        if self._python is None:  # the robot builds; health says why
            reason = (
                "MediaPipe Pose is not installed: run `python -m poppy_core.sensors.pose_venv` "
                "(or give the sensor a 'python' with MediaPipe 0.10.21)"
            )
            logger.warning("%s %s is not available: %s", self.kind, name, reason)
            self.fail(reason)
        elif not self._python.is_file():
            reason = f"no interpreter {self._python} (the sensor's 'python')"
            logger.warning("%s %s is not available: %s", self.kind, name, reason)
            self.fail(reason)

    @property
    def camera(self) -> Camera:
        """The camera looked through."""
        return self.cameras[0]

    @property
    def tracked_skeleton(self) -> dict[Any, Skeleton]:
        """``{0: Skeleton}`` while a person is seen, else empty (as a Kinect's: no wait)."""
        self.start()
        return {s.user_id: s for s in self._found}

    def remove_all_users(self) -> None:
        """Forget the skeleton seen last (pypot's; the next frame brings it back)."""
        self._found = []

    def find(self, image: np.ndarray, camera: Camera) -> list[Skeleton]:
        if self._worker is None:
            if self._python is None:
                raise SensorError(self.health().last_error, sensor=self.name)
            self._worker = PoseWorker(self._python, static=self.static)
            logger.info("%s %s: MediaPipe %s", self.kind, self.name, self._worker.version)
        rgb = image[:, :, ::-1] if image.ndim == 3 else np.repeat(image[:, :, None], 3, axis=2)
        try:
            answer = self._worker.estimate(rgb)
        except SensorLost:
            self._drop()
            raise
        if answer is None:
            return []
        height, width = image.shape[:2]
        skeleton = skeleton_from_landmarks(
            answer["landmarks"], answer["world"], (width, height), camera.latest().time_s
        )
        return [skeleton]

    def reconnect(self) -> None:
        if self._python is None:
            raise SensorError("no MediaPipe", sensor=self.name)
        try:
            self._worker = PoseWorker(self._python, static=self.static)
        except SensorLost as exc:
            raise SensorError(str(exc), sensor=self.name) from None

    def _drop(self) -> None:
        worker, self._worker = self._worker, None
        if worker is not None:
            worker.close()

    def release(self) -> None:
        self._drop()
