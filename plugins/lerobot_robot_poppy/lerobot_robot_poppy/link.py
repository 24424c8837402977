"""The one place the plugin reaches a Poppy robot: built by poppy, served, or simulated.

``open_link(fields, config)`` gives a :class:`LocalLink` (poppy's ``from_config`` on a serial
port or the simulation) or a :class:`RemoteLink` (``poppy_core.remote.RemoteRobot`` on
``http://`` or ``zenoh:``). Both read present positions, write goals clamped to the joints'
angle limits (poppy's one rule, ``trajectory.clamp_goal``), set compliance and give frames.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

DEFAULT_PROFILES = {
    "poppy_ergo_jr": "ergo-jr",
    "poppy_torso": "torso",
    "poppy_humanoid": "humanoid",
}
FIRST_FRAME_S = 30.0
SIM_PORTS = {"sim": "mujoco", "sim:mujoco": "mujoco", "sim:ideal": "ideal"}


def is_remote(port: str) -> bool:
    """True for a robot served by `poppy serve` (HTTP or Zenoh)."""
    return port.startswith(("http://", "https://", "zenoh:"))


def load_config(profile: str, kind: str) -> Any:
    """Poppy's config of ``profile`` (a name or a file), or of the type's own profile."""
    from pathlib import Path

    from poppy_core.robot import load_config as load_file
    from poppy_core.robot import load_profile

    name = profile or DEFAULT_PROFILES[kind]
    path = Path(name).expanduser()
    return load_file(path) if path.is_file() else load_profile(name)


def joints(config: Any, group: str) -> list[str]:
    """The joints the device uses: the group's, or every motor of the config."""
    if not group:
        return list(config.motors)
    if group not in config.motorgroups and group not in config.motors:
        raise ValueError(
            f"no motor group {group!r} (groups: {', '.join(config.motorgroups) or 'none'})"
        )
    return config.resolve_group(group)


def limits_of(config: Any, names: Sequence[str]) -> dict[str, tuple[float, float] | None]:
    """Each joint's angle limits in the user frame (None: a wheel)."""
    return {
        n: None if config.motors[n].wheel_mode else config.motors[n].user_angle_limit for n in names
    }


def ports_of(port: str, config: Any) -> str | dict[str, str]:
    """``port``, or controller -> port from ``CONTROLLER=PORT,CONTROLLER=PORT`` (a robot of
    several buses, the Humanoid's ``upper_body_controller`` and ``lower_body_controller``)."""
    parts = [p.strip() for p in port.split(",")]
    pairs = [p.partition("=") for p in parts]
    several = len(config.controllers) > 1
    if len(parts) < 2 and not several and not (pairs[0][1] and pairs[0][0] in config.controllers):
        return port
    ports: dict[str, str] = {}
    for name, sep, value in pairs:
        if not sep or name not in config.controllers or not value:
            raise ValueError(
                f"port {port!r}: this robot has {len(config.controllers)} buses: give "
                "CONTROLLER=PORT for each, comma-separated "
                f"(controllers: {', '.join(config.controllers)})"
            )
        ports[name] = value
    return ports


class LocalLink:
    """A robot poppy builds in this process: a serial port, or the simulation."""

    def __init__(self, config: Any, port: str, cameras: Sequence[str]) -> None:
        from poppy_core import from_config
        from poppy_core.robot import with_ports

        sim = SIM_PORTS.get(port, False)
        if not sim:
            config = with_ports(config, ports_of(port, config), source="LeRobot config")
        self.robot = from_config(config, sim=sim, sensors=bool(cameras), start_defaults=False)
        self._cameras: dict[str, Any] = {}
        try:
            by_name = {s.name: s for s in self.robot.sensors}
            for name in cameras:
                if name not in by_name:
                    raise ValueError(
                        f"the robot has no camera {name!r} "
                        f"(sensors: {', '.join(by_name) or 'none'})"
                    )
                self._cameras[name] = by_name[name]
        except BaseException:
            self.robot.close()
            raise

    def positions(self, names: Sequence[str]) -> dict[str, float]:
        return {n: float(self.robot.motor(n).present_position) for n in names}

    def send(self, goals: Mapping[str, float]) -> None:
        for name, value in goals.items():
            self.robot.motor(name).goal_position = value

    def set_compliant(self, names: Sequence[str], compliant: bool) -> None:
        for name in names:
            self.robot.motor(name).compliant = compliant

    def frame(self, name: str, timeout_s: float = FIRST_FRAME_S) -> np.ndarray:
        """The camera's latest frame, RGB (poppy's are BGR, as OpenCV's); the first waits up to
        ``timeout_s`` (a camera opening, a renderer made on a busy computer)."""
        image = self._cameras[name].latest(timeout_s).image
        return np.ascontiguousarray(image[..., ::-1])

    def start_primitive(self, name: str) -> Any:
        primitive = getattr(self.robot, name, None)
        if primitive is None or not hasattr(primitive, "start"):
            raise ValueError(f"the robot has no primitive {name!r}")
        primitive.start()
        return primitive

    def close(self) -> None:
        self.robot.close()


class RemoteLink:
    """A robot served by `poppy serve --http` or `--zenoh` (``RemoteRobot``): its server
    clamps goals too, and owns its cameras (read through its ``frame.png`` route) and
    calibration."""

    def __init__(
        self,
        port: str,
        names: Sequence[str],
        cameras: Sequence[str],
        zenoh_connect: Sequence[str] = (),
    ) -> None:
        import os

        from poppy_core.remote import RemoteRobot
        from poppy_core.remote.zenoh_client import client_settings

        if zenoh_connect and not port.startswith("zenoh:"):
            raise ValueError(f"zenoh_connect is for a zenoh:NAME port, not {port}")
        zenoh = client_settings(tuple(zenoh_connect)) if port.startswith("zenoh:") else None
        token = os.environ.get("POPPY_TOKEN") or None
        self.robot = RemoteRobot(port, token=token, zenoh=zenoh)
        missing = [n for n in names if n not in {m.name for m in self.robot.motors}]
        if missing:
            self.robot.close()
            raise ValueError(f"the robot at {port} lacks the motors {', '.join(missing)}")
        self._cameras = list(cameras)
        if cameras:
            served = self.robot.camera_names()
            unknown = [n for n in cameras if n not in served]
            if unknown:
                self.robot.close()
                raise ValueError(
                    f"the robot at {port} has no camera {unknown[0]!r} "
                    f"(cameras: {', '.join(served) or 'none'})"
                )

    def positions(self, names: Sequence[str]) -> dict[str, float]:
        state = self.robot.state()
        return {n: float(state[n]["present_position"]) for n in names}

    def send(self, goals: Mapping[str, float]) -> None:
        for name, value in goals.items():
            self.robot.motor(name).goal_position = value

    def set_compliant(self, names: Sequence[str], compliant: bool) -> None:
        for name in names:
            self.robot.motor(name).compliant = compliant

    def frame(self, name: str, timeout_s: float = FIRST_FRAME_S) -> np.ndarray:
        """The served camera's latest frame, RGB: its ``frame.png`` route (over HTTP or
        Zenoh, lossless), decoded; the first waits for the camera on the robot's side."""
        import cv2

        if name not in self._cameras:
            raise KeyError(name)
        data = np.frombuffer(self.robot.camera_image(name, "png"), np.uint8)
        image = cv2.imdecode(data, cv2.IMREAD_COLOR)
        if image is None:
            raise ValueError(f"camera {name!r}: the robot's frame is not a PNG image")
        return np.ascontiguousarray(image[..., ::-1])

    def start_primitive(self, name: str) -> Any:
        primitive = getattr(self.robot, name)
        primitive.start()
        return primitive

    def close(self) -> None:
        self.robot.close()


def open_link(
    config: Any,
    port: str,
    names: Sequence[str],
    cameras: Sequence[str],
    zenoh_connect: Sequence[str] = (),
) -> Any:
    """The robot at ``port`` (see the config's ``port`` and ``zenoh_connect`` fields)."""
    if is_remote(port):
        return RemoteLink(port, names, cameras, zenoh_connect)
    if zenoh_connect:
        raise ValueError(f"zenoh_connect is for a zenoh:NAME port, not {port}")
    return LocalLink(config, port, cameras)
