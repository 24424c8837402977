"""``MarkerDetector``: markers in the frames of one or more cameras, in the background.

``FrameDetector`` is what every detector on camera frames shares (``FaceDetector`` too).

pypot's ``MarkerDetector`` (``cameras``, ``freq``; register ``markers``) with ArUco and Hamming
markers, poses when a camera's calibration is known, and named cards: ``sees("caribou")`` is
the library call behind Snap!'s ``/detect/<card>`` block.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import ClassVar, Generic, TypeVar

import numpy as np

from poppy_core.errors import SensorError, UnknownCardError
from poppy_core.sensors.base import FIRST_VALUE_TIMEOUT_S, Sensor, SensorHealth
from poppy_core.sensors.camera import Camera
from poppy_core.sensors.markers import (
    DEFAULT_DICTIONARY,
    DEFAULT_MARKER_SIZE_M,
    FAMILIES,
    Marker,
    MarkerFinder,
)

logger = logging.getLogger(__name__)

DEFAULT_FREQ_HZ = 5.0
STALE_FRAME_S = 2.0
"""Frames older than this (a lost camera) show nothing."""

T = TypeVar("T")


class FrameDetector(Sensor, Generic[T]):
    """What a detector of things in camera frames shares: its cameras, looking at each new frame
    once, stale frames ignored. Subclasses implement ``find``.

    Args:
        name: the sensor's name.
        cameras: the cameras to look through.
        freq: detections per second.
    """

    what: ClassVar[str] = "things"
    """What it detects, for messages."""

    def __init__(self, name: str, cameras: Sequence[Camera], freq: float) -> None:
        super().__init__(name, freq)
        if not cameras:
            raise SensorError(f"sensor {name!r}: a {self.kind} needs a camera", sensor=name)
        self.cameras = list(cameras)
        self._found: list[T] = []
        self._seen: dict[str, tuple[int, list[T]]] = {}
        self._waited = False
        self._said_slow = False

    def find(self, image: np.ndarray, camera: Camera) -> list[T]:
        """What is in one frame of ``camera`` (called in the detector's thread or by ``detect``)."""
        raise NotImplementedError

    def _in(self, camera: Camera) -> list[T]:
        frame = camera.latest()
        number, found = self._seen.get(camera.name, (0, []))
        if number != frame.number:  # a new frame: look again
            found = self.find(frame.image, camera)
            self._seen[camera.name] = (frame.number, found)
        return found

    def update(self) -> None:
        found: list[T] = []
        for camera in self.cameras:
            if camera.clock_s() - camera.latest().time_s > STALE_FRAME_S:
                continue
            found.extend(self._in(camera))
        self._found = found

    def health(self) -> SensorHealth:
        """Its own health, lost while a camera it looks through is lost (that camera's reason)."""
        own = super().health()
        if not own.connected:
            return own
        lost = [(camera.name, camera.health()) for camera in self.cameras]
        lost = [(name, health) for name, health in lost if not health.connected]
        if not lost:
            return own
        reason = "; ".join(f"camera {name!r} lost: {h.last_error}" for name, h in lost)
        return replace(
            own,
            connected=False,
            down_s=max(h.down_s for _, h in lost),
            last_error=reason,
        )

    def found(self) -> list[T]:
        """What the latest frames hold (the first call starts the detector and waits).

        A camera that is up but slow to give its first frame (a simulated camera starting its
        renderer on a busy machine) is not a failure: after one wait, nothing seen yet is what
        is found (pypot's detectors read an empty list until their first detection), with one
        WARNING; the following calls do not wait again.

        Raises:
            SensorError: the detector failed for good, or one of its cameras is lost.
        """
        try:
            self.wait_first(0.0 if self._waited else FIRST_VALUE_TIMEOUT_S * 2)
        except SensorError:
            self._waited = True
            if self._fatal or not all(camera.health().connected for camera in self.cameras):
                raise
            if not self._said_slow:
                self._said_slow = True
                logger.warning(
                    "%s %s: no frame yet from its cameras; nothing seen so far",
                    self.kind,
                    self.name,
                )
            return []
        return list(self._found)

    def detect(self, camera: Camera | None = None) -> list[T]:
        """What ``camera``'s latest frame holds (the first camera by default): detected now, in
        this thread, unless the background detection already looked at that frame."""
        return list(self._in(camera or self.cameras[0]))


class MarkerDetector(FrameDetector[Marker]):
    """Detects markers in the latest frames of ``cameras`` at ``freq`` Hz.

    Args:
        name: the sensor's name (``marker_detector``).
        cameras: the cameras to look through.
        freq: detections per second.
        cards: card name -> the marker ids printed on it (``{"caribou": [221052793]}``).
        dictionary: the ArUco dictionary.
        marker_size: side of the printed markers in metres (for poses).
        families: ``"aruco"``, ``"hamming"`` or both.
    """

    registers: ClassVar[tuple[str, ...]] = ("markers", "cards")
    what: ClassVar[str] = "markers"

    def __init__(
        self,
        name: str,
        cameras: Sequence[Camera],
        freq: float = DEFAULT_FREQ_HZ,
        *,
        cards: Mapping[str, Sequence[int]] | None = None,
        dictionary: str = DEFAULT_DICTIONARY,
        marker_size: float = DEFAULT_MARKER_SIZE_M,
        families: Sequence[str] = FAMILIES,
    ) -> None:
        super().__init__(name, cameras, freq)
        self.finder = MarkerFinder(dictionary, marker_size, tuple(families))
        self.card_ids: dict[str, list[int]] = {k: list(v) for k, v in (cards or {}).items()}
        if self.finder.missing is not None:  # no OpenCV: the robot builds, health says why
            logger.warning("%s %s is not available: %s", self.kind, name, self.finder.missing)
            self.fail(str(self.finder.missing))

    def start(self) -> None:
        """Start detecting (the first read does it).

        Raises:
            MissingExtraError: OpenCV (the ``vision`` extra) is not installed, in one line.
            SensorError: the detector was closed.
        """
        self.finder.ready()
        super().start()

    def detect(self, camera: Camera | None = None) -> list[Marker]:
        self.finder.ready()
        return super().detect(camera)

    def find(self, image: np.ndarray, camera: Camera) -> list[Marker]:
        return self.finder.find(image, camera.calibration, camera.name)

    # -- registers -------------------------------------------------------------------------------

    @property
    def markers(self) -> list[Marker]:
        """The markers seen in the latest frames (the first read starts the detector and waits).

        Raises:
            SensorError: no detection ran in time (a camera gives no frame).
        """
        return self.found()

    @property
    def cards(self) -> list[str]:
        """Names of the cards seen now."""
        ids = {m.id for m in self.markers}
        return [card for card, card_ids in self.card_ids.items() if ids & set(card_ids)]

    # -- library calls -----------------------------------------------------------------------------

    def sees(self, card_or_id: str | int) -> bool:
        """Whether a card (by name) or a marker id is in view now (Snap!'s ``/detect/<card>``).

        Raises:
            SensorError: an unknown card name (the known ones are listed).
        """
        if isinstance(card_or_id, int):
            wanted = {card_or_id}
        elif card_or_id.strip().lstrip("-").isascii() and card_or_id.strip().lstrip("-").isdigit():
            wanted = {int(card_or_id)}
        elif card_or_id in self.card_ids:
            wanted = set(self.card_ids[card_or_id])
        else:
            known = list(self.card_ids)
            listed = ", ".join(known) or "none"
            raise UnknownCardError(
                f"no card {card_or_id!r} (cards: {listed}; or give a marker id)",
                name=str(card_or_id),
                known=known,
                sensor=self.name,
            )
        return any(m.id in wanted for m in self.markers)
