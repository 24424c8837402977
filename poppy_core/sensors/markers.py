"""Find markers in a frame: ArUco (OpenCV's aruco) and Hamming codes (pypot's cards); poses.

``MarkerFinder(dictionary, marker_size_m).find(frame, calibration)`` returns ``Marker``s: id,
family, corners and centre in pixels, ``position`` normalised to -1..1 (x right, y down, as
pypot's markers), and the pose in the camera's frame when the calibration is known.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from poppy_core.errors import MissingExtraError, SensorError
from poppy_core.extras import require
from poppy_core.sensors import hamming
from poppy_core.sensors.camera import CameraCalibration
from poppy_core.sensors.opencv import cv

DEFAULT_DICTIONARY = "DICT_4X4_50"
DEFAULT_MARKER_SIZE_M = 0.05
FAMILIES = ("aruco", "hamming")
_WARP_CELL_PX = 10
MIN_HAMMING_AREA = 0.002
"""Smallest Hamming marker looked for, as a fraction of the frame's area (hampy: 1 %)."""


@dataclass(frozen=True)
class MarkerPose:
    """Where a marker is in the camera's frame (OpenCV's: x right, y down, z forward)."""

    rvec: tuple[float, float, float]
    """Rotation vector (Rodrigues, radians)."""
    tvec: tuple[float, float, float]
    """Translation of the marker's centre, metres."""

    @property
    def distance_m(self) -> float:
        """Distance from the camera to the marker's centre."""
        return float(np.linalg.norm(self.tvec))


@dataclass(frozen=True)
class Marker:
    """A marker seen in one frame."""

    id: int
    family: str
    corners: tuple[tuple[float, float], ...]
    """Four corners in pixels, clockwise from the marker's top left."""
    center: tuple[float, float]
    position: tuple[float, float]
    """Centre normalised to -1..1 of the frame (x right, y down), as pypot's ``position``."""
    camera: str = ""
    pose: MarkerPose | None = None

    def as_dict(self) -> dict[str, Any]:
        """Plain data (JSON), with pypot's ``id`` and ``position``."""
        data: dict[str, Any] = {
            "id": self.id,
            "family": self.family,
            "position": [round(v, 4) for v in self.position],
            "center": [round(v, 1) for v in self.center],
            "corners": [[round(x, 1), round(y, 1)] for x, y in self.corners],
            "camera": self.camera,
        }
        if self.pose is not None:
            data["pose"] = {
                "rvec": [round(v, 5) for v in self.pose.rvec],
                "tvec": [round(v, 5) for v in self.pose.tvec],
                "distance_m": round(self.pose.distance_m, 5),
            }
        return data


def aruco_dictionary(name: str) -> Any:
    """OpenCV's predefined ArUco dictionary called ``name`` (``DICT_4X4_50``...).

    Raises:
        SensorError: no such dictionary.
    """
    cv2 = cv()
    key = name.upper()
    if not key.startswith("DICT_") or not hasattr(cv2.aruco, key):
        known = sorted(k for k in dir(cv2.aruco) if k.startswith("DICT_"))
        raise SensorError(f"unknown ArUco dictionary {name!r} (one of {', '.join(known)})")
    return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, key))


def aruco_image(marker_id: int, dictionary: str = DEFAULT_DICTIONARY, size_px: int = 200) -> Any:
    """A printable grey image of ArUco marker ``marker_id`` with a white margin of one cell.

    Raises:
        SensorError: unknown dictionary or an id it does not hold.
    """
    cv2 = cv()
    chosen = aruco_dictionary(dictionary)
    count = chosen.bytesList.shape[0]
    if not 0 <= marker_id < count:
        raise SensorError(f"{dictionary} holds ids 0-{count - 1}, not {marker_id}")
    cells = chosen.markerSize + 2
    inner = cv2.aruco.generateImageMarker(chosen, marker_id, size_px, borderBits=1)
    margin = max(1, size_px // cells)
    return cv2.copyMakeBorder(inner, margin, margin, margin, margin, cv2.BORDER_CONSTANT, value=255)


def marker_image(
    marker_id: int, family: str = "aruco", dictionary: str = DEFAULT_DICTIONARY, size_px: int = 200
) -> Any:
    """A printable grey image of a marker of either family (white margin included).

    Raises:
        SensorError: unknown family, dictionary or id.
    """
    if family == "aruco":
        return aruco_image(marker_id, dictionary, size_px)
    if family == "hamming":
        try:
            return hamming.image(marker_id, cell_px=max(2, size_px // hamming.GRID))
        except ValueError as exc:
            raise SensorError(str(exc)) from None
    raise SensorError(f"unknown marker family {family!r} (one of {', '.join(FAMILIES)})")


def _clockwise(quad: np.ndarray) -> np.ndarray:
    """The quad's corners in clockwise order as seen in the image (y down)."""
    x, y = quad[:, 0], quad[:, 1]
    area = float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    return quad if area > 0 else quad[::-1].copy()


def _quads(grey: np.ndarray) -> list[np.ndarray]:
    """Convex quadrilaterals outlining dark regions, big enough to hold a 9×9 code."""
    cv2 = cv()
    block = max(3, min(grey.shape[:2]) // 8) | 1
    binary = cv2.adaptiveThreshold(
        grey, 255, cv2.ADAPTIVE_THRESH_MEAN_C, cv2.THRESH_BINARY_INV, block, 7
    )
    contours, _ = cv2.findContours(binary, cv2.RETR_LIST, cv2.CHAIN_APPROX_SIMPLE)
    min_area = grey.shape[0] * grey.shape[1] * MIN_HAMMING_AREA
    quads = []
    for contour in contours:
        if cv2.contourArea(contour) < min_area:
            continue
        approx = cv2.approxPolyDP(contour, 0.03 * cv2.arcLength(contour, True), True)
        if len(approx) == 4 and cv2.isContourConvex(approx):
            quads.append(_clockwise(approx.reshape(4, 2).astype(np.float32)))
    return quads


class MarkerFinder:
    """Finds markers in frames (no thread: ``MarkerDetector`` runs one in the background).

    Args:
        dictionary: the ArUco dictionary (``DICT_4X4_50``...).
        marker_size_m: side of the printed markers (black square), for poses.
        families: ``"aruco"``, ``"hamming"`` or both.

    OpenCV is needed only to find markers: without the ``vision`` extra the finder is made,
    ``missing`` says why it cannot work, and ``find`` raises ``MissingExtraError``.

    Raises:
        SensorError: unknown dictionary or family, or a size that is not positive.
    """

    def __init__(
        self,
        dictionary: str = DEFAULT_DICTIONARY,
        marker_size_m: float = DEFAULT_MARKER_SIZE_M,
        families: tuple[str, ...] = FAMILIES,
    ) -> None:
        unknown = [f for f in families if f not in FAMILIES]
        if unknown or not families:
            raise SensorError(f"marker families are {', '.join(FAMILIES)}, got {families!r}")
        if not marker_size_m > 0:
            raise SensorError(f"marker size must be a positive length in m, got {marker_size_m}")
        self.dictionary = dictionary
        self.marker_size_m = float(marker_size_m)
        self.families = tuple(families)
        self._detector: Any = None
        self.missing: MissingExtraError | None = None
        """Why the finder cannot work (OpenCV is not installed), None when it can."""
        half = self.marker_size_m / 2
        self._object_points = np.array(
            [[-half, half, 0], [half, half, 0], [half, -half, 0], [-half, -half, 0]],
            dtype=np.float32,
        )
        try:
            self.ready()
        except MissingExtraError as exc:
            self.missing = exc

    def ready(self) -> None:
        """Make OpenCV's ArUco detector if not yet made (``find`` does it first).

        Raises:
            MissingExtraError: OpenCV (the ``vision`` extra) is not installed, in one line.
            SensorError: an unknown dictionary.
        """
        if self._detector is not None:
            return
        require("cv2", extra="vision", feature="marker detection")
        cv2 = cv()
        self._detector = cv2.aruco.ArucoDetector(
            aruco_dictionary(self.dictionary), cv2.aruco.DetectorParameters()
        )
        self.missing = None

    def find(
        self, frame: np.ndarray, calibration: CameraCalibration | None = None, camera: str = ""
    ) -> list[Marker]:
        """Every marker in ``frame`` (BGR or grey), with poses when ``calibration`` is given.

        Raises:
            MissingExtraError: OpenCV (the ``vision`` extra) is not installed.
        """
        self.ready()
        cv2 = cv()
        grey = frame if frame.ndim == 2 else cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
        corners, ids, _ = self._detector.detectMarkers(grey)
        found: list[tuple[int, str, np.ndarray]] = []
        if "aruco" in self.families and ids is not None:
            for quad, marker_id in zip(corners, ids.ravel(), strict=True):
                found.append((int(marker_id), "aruco", quad.reshape(4, 2)))
        if "hamming" in self.families:
            seen: set[int] = set()
            for square in _quads(grey):
                for marker_id in self._hamming_ids(grey, square):
                    if marker_id not in seen:
                        seen.add(marker_id)
                        found.append((marker_id, "hamming", square))
        height, width = grey.shape[:2]
        return [
            self._marker(marker_id, family, quad, width, height, calibration, camera)
            for marker_id, family, quad in found
        ]

    def _hamming_ids(self, grey: np.ndarray, quad: np.ndarray) -> list[int]:
        cv2 = cv()
        side = hamming.GRID * _WARP_CELL_PX
        target = np.array(
            [[0, 0], [side - 1, 0], [side - 1, side - 1], [0, side - 1]], dtype=np.float32
        )
        warp = cv2.getPerspectiveTransform(quad, target)
        square = cv2.warpPerspective(grey, warp, (side, side))
        return hamming.decode_rotations(hamming.read_cells(square))

    def _marker(
        self,
        marker_id: int,
        family: str,
        quad: np.ndarray,
        width: int,
        height: int,
        calibration: CameraCalibration | None,
        camera: str,
    ) -> Marker:
        center = quad.mean(axis=0)
        position = (2.0 * float(center[0]) / width - 1.0, 2.0 * float(center[1]) / height - 1.0)
        pose = None
        if calibration is not None:
            pose = self._pose(quad, calibration)
        return Marker(
            id=marker_id,
            family=family,
            corners=tuple((float(x), float(y)) for x, y in quad),
            center=(float(center[0]), float(center[1])),
            position=position,
            camera=camera,
            pose=pose,
        )

    def _pose(self, quad: np.ndarray, calibration: CameraCalibration) -> MarkerPose | None:
        cv2 = cv()
        ok, rvec, tvec = cv2.solvePnP(
            self._object_points,
            quad.astype(np.float32),
            calibration.camera_matrix,
            calibration.dist_coeffs,
            flags=cv2.SOLVEPNP_IPPE_SQUARE,
        )
        if not ok:
            return None
        r = rvec.ravel()
        t = tvec.ravel()
        return MarkerPose(
            (float(r[0]), float(r[1]), float(r[2])), (float(t[0]), float(t[1]), float(t[2]))
        )
