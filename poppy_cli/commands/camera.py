"""`poppy camera ...`: list cameras, take a snapshot, detect markers (a device or a simulation)."""

from __future__ import annotations

import time
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from poppy_cli.options import ConfigOpt, JsonOpt, ProfileOpt, SimOpt
from poppy_cli.output import EXIT_USAGE, console, error_line, print_json, styled
from poppy_core import checks
from poppy_core.errors import ArgumentError

if TYPE_CHECKING:
    from collections.abc import Iterator

    from poppy_core.sensors import Camera, MarkerDetector

app = typer.Typer(
    help="Cameras: list them, take a snapshot, detect markers (a device, or --sim mujoco).",
    no_args_is_help=True,
)

DeviceOpt = typer.Option(
    None, "--device", help="Camera index (0 is /dev/video0), device path or video file."
)
SizeOpt = typer.Option(None, "--resolution", help="WIDTHxHEIGHT, e.g. 640x480.")
MarkerOpt = typer.Option(
    None, "--marker", help="With --sim mujoco: hold ArUco marker ID 25 cm in front of the camera."
)
CardOpt = typer.Option(
    None, "--card", help="With --sim mujoco: hold a Poppy card (caribou, tetris, lapin) in view."
)
SNAPSHOT_TYPES = (".png", ".jpg", ".jpeg")
MAX_SIDE = 8192
"""The widest image side asked of a camera (8K)."""


def _resolution(text: str | None) -> tuple[int, int] | None:
    if text is None:
        return None
    width, _, height = text.lower().partition("x")
    if not (width.isdigit() and height.isdigit()):
        raise typer.BadParameter(f"{text!r}: give WIDTHxHEIGHT, e.g. 640x480")
    try:  # checked before a camera or a renderer is asked for that many pixels
        return (
            checks.count(int(width), 1, MAX_SIDE, "the width"),
            checks.count(int(height), 1, MAX_SIDE, "the height"),
        )
    except (ArgumentError, ValueError) as exc:
        raise typer.BadParameter(f"{text!r}: {exc}") from None


def _usage(message: str) -> None:
    error_line(message)
    raise typer.Exit(EXIT_USAGE)


FRAME_S = 30.0
"""The longest wait for a camera's next frame."""
SIM_FIRST_FRAME_S = 180.0
"""The longest wait for a simulated camera's first frame: it includes building the renderer,
with a software renderer 2 s on an idle 2-core machine, 6 s beside four busy loops, past 30 s at
load 20: a slow or busy machine is not a broken camera."""


def _first_frame_s(sim: str | None) -> float:
    """The wait for the first frame of the camera ``_source`` opens."""
    return FRAME_S if sim is None else SIM_FIRST_FRAME_S


@contextmanager
def _source(
    device: str | None,
    profile: str | None,
    config_file: Path | None,
    sim: str | None,
    resolution: tuple[int, int] | None,
    marker: int | None = None,
    card: str | None = None,
) -> Iterator[tuple[Camera, MarkerDetector | None]]:
    """The camera (and a marker detector) of a device, or of a simulated robot."""
    from poppy_core.sensors import MarkerDetector
    from poppy_core.sensors.opencv_capture import OpenCVCamera

    if (marker is not None or card) and sim != "mujoco":
        _usage("--marker and --card put a card in a simulated scene: add --sim mujoco")
    if sim is None:
        camera: Camera = OpenCVCamera(
            "camera", device if device is not None else 0, 20.0, resolution
        )
        detector = MarkerDetector("marker_detector", [camera], 5.0)
        try:
            yield camera, detector
        finally:
            detector.close()
            camera.close()
        return
    if device is not None:
        _usage("--device names a real camera: leave out --sim")
    from poppy_cli.robots import robot_config, start_robot
    from poppy_core.robot import RobotConfig
    from poppy_core.sensors import Camera

    config = robot_config(profile, config_file, None)
    if resolution is not None:
        data = config.to_dict()
        for spec in data.get("sensors", {}).values():
            if spec.get("type") in ("OpenCVCamera", "DummyCamera"):
                spec["resolution"] = list(resolution)
        config = RobotConfig.from_dict(data, source="command line")
    with start_robot(config, sim, sensors=True) as robot:
        cameras = [s for s in robot.sensors if isinstance(s, Camera)]
        if not cameras:
            _usage("this robot's config has no camera (its sensors section)")
        camera = cameras[0]
        found = [s for s in robot.sensors if isinstance(s, MarkerDetector)]
        if sim == "mujoco":
            _pose_for_camera(robot, marker, card, found[0] if found else None)
        yield camera, (found[0] if found else MarkerDetector("marker_detector", [camera], 5.0))


def _pose_for_camera(
    robot: Any, marker: int | None, card: str | None, detector: MarkerDetector | None
) -> None:
    """Stand the simulated robot at its zero pose (head ahead) and hold the cards asked for."""
    import numpy as np

    robot.compliant = False
    robot.goto_position({m.name: 0.0 for m in robot.motors}, 0.5, wait=True)
    time.sleep(0.3)
    sim = robot.simulation
    with sim.lock:
        import mujoco

        index = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
        matrix = np.asarray(sim.data.cam_xmat[index]).reshape(3, 3)
        ahead = np.asarray(sim.data.cam_xpos[index]) - 0.25 * matrix[:, 2]
    if marker is not None:
        sim.add_marker("marker_card", marker, tuple(ahead - 0.045 * matrix[:, 0]), size=0.05)
    if card:
        ids = detector.card_ids.get(card) if detector is not None else None
        if not ids:
            known = ", ".join(detector.card_ids) if detector is not None else "none"
            _usage(f"no card {card!r} in this robot's profile (cards: {known})")
            return
        sim.add_marker(
            card, ids[0], tuple(ahead + 0.045 * matrix[:, 0]), size=0.05, family="hamming"
        )


def list_cameras(json_output: bool = JsonOpt) -> None:
    """The video devices of this machine (V4L2), with their names."""
    from poppy_core.sensors.opencv_capture import list_devices

    devices = list_devices()
    if json_output:
        print_json(devices)
        return
    if not devices:
        console.print("no camera found (/dev/video*); plug one in")
        return
    from rich.table import Table

    table = Table("index", "device", "name")
    for device in devices:
        table.add_row(str(device["index"]), device["device"], device["name"])
    console.print(table)


def snapshot(
    output: Path = typer.Option(
        ..., "--output", "-o", help="Image file (.png or .jpg), or a folder (snapshot.png)."
    ),
    device: str | None = DeviceOpt,
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    sim: str | None = SimOpt,
    resolution: str | None = SizeOpt,
    marker: int | None = MarkerOpt,
    card: str | None = CardOpt,
    force: bool = typer.Option(False, "--force", "-f", help="Replace an existing file."),
) -> None:
    """Save one frame: of a device (default /dev/video0), or of a simulated robot's camera.

    An existing file is replaced only with --force; a folder, a link, a FIFO or a device never.
    """
    from poppy_core.files import output_path, write_file
    from poppy_core.sensors.opencv import encode_image

    target = output_path(output, default_name="snapshot.png", replace=force)  # before the camera
    if target.suffix.lower() not in SNAPSHOT_TYPES:
        _usage(f"{target}: the image type comes from its name: use .png or .jpg")
    size = _resolution(resolution)
    with _source(device, profile, config_file, sim, size, marker, card) as (camera, _):
        first = camera.next_frame(-1, timeout_s=_first_frame_s(sim))
        frame = camera.next_frame(first.number, timeout_s=FRAME_S)  # after the cards were put
        data = encode_image(frame.image, target.suffix.lower())
    written = write_file(target, data, replace=force)
    height, width = frame.image.shape[:2]
    console.print(styled("saved {} ({}x{})", written, width, height))


def detect(
    device: str | None = DeviceOpt,
    profile: str | None = ProfileOpt,
    config_file: Path | None = ConfigOpt,
    sim: str | None = SimOpt,
    resolution: str | None = SizeOpt,
    marker: int | None = MarkerOpt,
    card: str | None = CardOpt,
    watch: bool = typer.Option(False, "--watch", "-w", help="Keep detecting until Ctrl-C."),
    json_output: bool = JsonOpt,
) -> None:
    """The markers the camera sees (ArUco and Poppy cards): id, card, position, distance."""
    size = _resolution(resolution)
    with _source(device, profile, config_file, sim, size, marker, card) as (camera, detector):
        assert detector is not None
        names = {i: name for name, ids in detector.card_ids.items() for i in ids}
        number = camera.next_frame(-1, timeout_s=_first_frame_s(sim)).number
        while True:
            frame = camera.next_frame(number, timeout_s=FRAME_S)
            number = frame.number
            markers = detector.finder.find(frame.image, camera.calibration, camera.name)
            if json_output:
                print_json([{**m.as_dict(), "card": names.get(m.id)} for m in markers])
            else:
                _print_markers(markers, names)
            if not watch:
                return
            time.sleep(0.2)


def _print_markers(markers: list[Any], names: dict[int, str]) -> None:
    from rich.table import Table

    if not markers:
        console.print("no marker in view")
        return
    table = Table("id", "family", "card", "position x, y", "distance m")
    for m in markers:
        distance = f"{m.pose.distance_m:.3f}" if m.pose is not None else "-"
        table.add_row(
            str(m.id),
            m.family,
            names.get(m.id, ""),
            f"{m.position[0]:+.2f}, {m.position[1]:+.2f}",
            distance,
        )
    console.print(table)


app.command("list")(list_cameras)
app.command("snapshot")(snapshot)
app.command("detect")(detect)
