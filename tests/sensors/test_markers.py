"""Marker detection: ArUco and Hamming codes (pypot's cards) in frames, poses, cards by name."""

from __future__ import annotations

import logging
import threading

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from poppy_core.errors import SensorError
from poppy_core.sensors import CameraCalibration, DummyCamera, MarkerDetector, hamming
from poppy_core.sensors import camera as camera_module
from poppy_core.sensors import detector as detector_module
from poppy_core.sensors.base import SensorLost
from poppy_core.sensors.markers import MarkerFinder, marker_image
from tests.helpers.waiting import eventually

cv2 = pytest.importorskip("cv2")

CARIBOU = 221052793  # pypot 5.0.2, pypot/server/snap.py


@given(st.integers(1, hamming.MAX_ID - 2))
def test_hamming_codes_round_trip_in_any_rotation(marker_id: int) -> None:
    # ids 0 and 2**28 - 1 are all dark / all bright: refused, as hampy does
    code = hamming.encode(marker_id)
    assert hamming.decode(code) == marker_id
    for turn in range(4):
        assert marker_id in hamming.decode_rotations(np.rot90(code, turn))


@given(st.integers(1, hamming.MAX_ID - 2), st.integers(0, 6), st.integers(0, 6))
def test_a_flipped_cell_is_refused(marker_id: int, row: int, column: int) -> None:
    code = hamming.encode(marker_id).copy()
    code[row, column] ^= 1
    assert hamming.decode(code) is None


def scene(*markers: tuple[np.ndarray, int, int]) -> np.ndarray:
    """A grey BGR frame with marker images pasted at (row, column), seen at a slant."""
    canvas = np.full((480, 640), 190, np.uint8)
    for image, row, column in markers:
        canvas[row : row + image.shape[0], column : column + image.shape[1]] = image
    bgr = cv2.cvtColor(canvas, cv2.COLOR_GRAY2BGR)
    slant = cv2.getPerspectiveTransform(
        np.float32([[0, 0], [640, 0], [640, 480], [0, 480]]),
        np.float32([[30, 10], [600, 40], [620, 470], [10, 450]]),
    )
    return cv2.warpPerspective(bgr, slant, (640, 480), borderValue=(190, 190, 190))


def test_aruco_and_hamming_markers_are_found() -> None:
    frame = scene(
        (marker_image(7, size_px=120), 40, 40),
        (marker_image(CARIBOU, "hamming", size_px=180), 200, 300),
    )
    found = {(m.family, m.id): m for m in MarkerFinder().find(frame, camera="camera")}
    assert set(found) == {("aruco", 7), ("hamming", CARIBOU)}
    aruco = found[("aruco", 7)]
    assert aruco.position[0] < -0.3 and aruco.position[1] < -0.3  # top left
    assert aruco.pose is None  # no calibration given
    assert aruco.as_dict()["id"] == 7 and aruco.as_dict()["camera"] == "camera"
    assert len(aruco.corners) == 4


def test_only_the_asked_families_are_looked_for() -> None:
    frame = scene(
        (marker_image(7, size_px=120), 40, 40),
        (marker_image(CARIBOU, "hamming", size_px=180), 200, 300),
    )
    assert [m.id for m in MarkerFinder(families=("aruco",)).find(frame)] == [7]
    assert [m.id for m in MarkerFinder(families=("hamming",)).find(frame)] == [CARIBOU]


def test_a_pose_is_where_the_marker_was_put() -> None:
    # a 5 cm marker 40 cm in front of an ideal 60° camera, drawn by projecting its corners
    calibration = CameraCalibration.from_fov(640, 480, 60.0)
    side_px = 120
    image = marker_image(3, size_px=side_px)
    border = (image.shape[0] - side_px) // 2
    half = 0.025
    corners_3d = np.float32(
        [[-half, -half, 0.4], [half, -half, 0.4], [half, half, 0.4], [-half, half, 0.4]]
    )
    projected, _ = cv2.projectPoints(
        corners_3d, np.zeros(3), np.zeros(3), calibration.camera_matrix, calibration.dist_coeffs
    )
    far = border + side_px
    source = np.float32([[border, border], [far, border], [far, far], [border, far]])
    warp = cv2.getPerspectiveTransform(source, projected.reshape(4, 2).astype(np.float32))
    frame = cv2.warpPerspective(image, warp, (640, 480), borderValue=255)
    (marker,) = MarkerFinder(marker_size_m=0.05).find(frame, calibration)
    assert marker.id == 3 and marker.pose is not None
    assert marker.pose.distance_m == pytest.approx(0.4, rel=0.03)
    assert marker.pose.tvec[0] == pytest.approx(0.0, abs=0.005)


def test_unknown_dictionary_family_and_ids_are_refused() -> None:
    with pytest.raises(SensorError, match="unknown ArUco dictionary 'DICT_9X9'"):
        MarkerFinder("DICT_9X9")
    with pytest.raises(SensorError, match="marker families"):
        MarkerFinder(families=("qr",))
    with pytest.raises(SensorError, match="ids 0-49, not 50"):
        marker_image(50)
    with pytest.raises(SensorError, match="Hamming marker id"):
        marker_image(-1, "hamming")


def test_the_detector_names_cards() -> None:
    with DummyCamera("camera", (64, 48)) as camera:
        detector = MarkerDetector("marker_detector", [camera], 20.0, cards={"caribou": [CARIBOU]})
        with detector:
            assert detector.markers == [] and detector.cards == []
            assert detector.sees("caribou") is False
            assert detector.sees(7) is False and detector.sees("7") is False
            with pytest.raises(SensorError, match=r"no card 'rabbit' \(cards: caribou"):
                detector.sees("rabbit")
            with pytest.raises(SensorError, match="no card '³'"):
                detector.sees("³")  # a digit to str.isdigit, not to int()
            assert detector.health().ok and detector.health().target_hz == 20.0


class SlowToStart(DummyCamera):
    """A camera that is up but gives its first frame only when let (a renderer starting)."""

    def __init__(self, name: str) -> None:
        super().__init__(name, (64, 48))
        self.let = threading.Event()

    def grab(self) -> np.ndarray:
        if not self.let.wait(10.0):
            raise SensorError("test camera never let")
        return super().grab()


def test_a_camera_slow_to_give_its_first_frame_shows_nothing_instead_of_failing(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    # pypot's detectors read [] until their first detection; a primitive reading them in its
    # loop (poppy-ergo-jr's TrackingFeedback on a loaded MuJoCo) must not die of a slow start
    monkeypatch.setattr(detector_module, "FIRST_VALUE_TIMEOUT_S", 0.1)
    monkeypatch.setattr(camera_module, "FIRST_VALUE_TIMEOUT_S", 0.1)
    with SlowToStart("camera") as camera, caplog.at_level(logging.WARNING):
        detector = MarkerDetector("marker_detector", [camera], 20.0)
        with detector:
            assert detector.markers == []
            assert detector.markers == [] and detector.cards == []  # no second wait
            said = [r.getMessage() for r in caplog.records if "no frame yet" in r.getMessage()]
            assert said == [
                "MarkerDetector marker_detector: no frame yet from its cameras; nothing seen so far"
            ]
            camera.let.set()
            assert eventually(lambda: detector.health().ok, timeout_s=10)
            assert detector.markers == []  # looked at a black frame


class Unplugged(DummyCamera):
    """A camera whose cable is out: every grab finds it gone."""

    def grab(self) -> np.ndarray:
        raise SensorLost("unplugged")


def test_a_detector_whose_camera_is_lost_still_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(detector_module, "FIRST_VALUE_TIMEOUT_S", 0.1)
    with Unplugged("camera", (64, 48)) as camera:
        camera.start()
        assert eventually(lambda: not camera.health().connected, timeout_s=10)
        with (
            MarkerDetector("marker_detector", [camera], 20.0) as detector,
            pytest.raises(SensorError, match="marker_detector"),
        ):
            detector.markers  # noqa: B018
