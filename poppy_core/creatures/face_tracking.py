"""Ergo Jr and faces: ``face_tracking``, the head turns to keep a face in the middle of the view.

poppy-ergo-jr's behaviour of that name (attached when the robot has a face detector): the base
(m1) and the head follow the face. Here it aims the camera like ``marker_follow`` (through the
arm's kinematic chain, on the real robot and in MuJoCo), following the face nearest the one it
followed last, so two people in view do not make it hesitate (at start: the surest face).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from poppy_core.creatures.tracking import FOLLOWING_MOTORS, FollowInView

if TYPE_CHECKING:
    from poppy_core.robot import Robot

FACE_TRACKING_HZ = 2.0
"""The face detector's default rate: acting faster would apply the same sighting twice."""


class FaceTracking(FollowInView):
    """Turn the chain so that its camera keeps a face in the middle of the view.

    Args:
        robot: a robot with the chain, a camera at the chain's tip and a face detector.
        chain: the chain carrying the camera (looking along the tip's -z).
        detector: the face detector, or its sensor name.
        freq: updates per second (each acts on a frame taken after the last move ended).
        gain: the share of the seen error corrected per update (0..1].
        motors: the chain's joints that move.
    """

    def __init__(
        self,
        robot: Robot,
        chain: str = "chain",
        detector: Any = "face_detector",
        freq: float = FACE_TRACKING_HZ,
        gain: float = 0.7,
        motors: Sequence[str] = FOLLOWING_MOTORS,
    ) -> None:
        super().__init__(robot, chain, detector, freq, gain, motors)
        self._followed: tuple[float, float] | None = None

    def setup(self) -> None:
        super().setup()
        self._followed = None

    def pick(self, found: list[Any]) -> Any | None:
        """The face nearest the one followed last (at first the surest, then the biggest)."""
        if not found:
            return None
        if self._followed is None:
            face = max(found, key=lambda f: (f.hits, f.size))
        else:
            x, y = self._followed
            face = min(found, key=lambda f: (f.position[0] - x) ** 2 + (f.position[1] - y) ** 2)
        self._followed = (float(face.position[0]), float(face.position[1]))
        return face
