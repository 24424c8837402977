"""Poppy robots as LeRobot ``Robot``s: `poppy_ergo_jr`, `poppy_torso`, `poppy_humanoid`.

Observations and actions are the joints' positions in degrees, named ``NAME.pos`` (``m1.pos``),
as `poppy dataset record` names them, so datasets of either command agree; cameras are
``NAME`` frames (H, W, 3) RGB. Torque: ``connect`` makes the joints stiff (a follower holds
where it is, then goes where it is told); ``disconnect`` turns them compliant
(``disable_torque_on_disconnect``, the default) or leaves them stiff.
"""

from __future__ import annotations

import logging
from functools import cached_property
from typing import Any

from lerobot.cameras.utils import make_cameras_from_configs
from lerobot.processor import RobotAction, RobotObservation
from lerobot.robots import Robot
from lerobot.robots.utils import ensure_safe_goal_position
from lerobot.utils.decorators import check_if_already_connected, check_if_not_connected

from lerobot_robot_poppy import calibration, link
from lerobot_robot_poppy.config_poppy import (
    PoppyErgoJrConfig,
    PoppyFollowerFields,
    PoppyHumanoidConfig,
    PoppyTorsoConfig,
)

logger = logging.getLogger(__name__)


def with_camera_resolution(config: Any, names: list[str], resolution: list[int]) -> Any:
    """``config`` with its cameras ``names`` at ``resolution`` ([width, height])."""
    if not resolution:
        return config
    if len(resolution) != 2 or not all(8 <= v <= 4096 for v in resolution):
        raise ValueError(
            f"robot_camera_resolution: give [WIDTH, HEIGHT] in pixels, not {resolution}"
        )
    from poppy_core.robot import RobotConfig

    data = config.to_dict()
    for name in names:
        camera_shape(config, name)  # refuses a name that is not a camera
        data["sensors"][name]["resolution"] = [int(v) for v in resolution]
    return RobotConfig.from_dict(data, source="LeRobot config").with_folder(config.folder)


def camera_shape(config: Any, name: str) -> tuple[int, int, int]:
    """(H, W, 3) of the robot's own camera ``name``, from its config's ``resolution``."""
    sensors = config.to_dict().get("sensors") or {}
    spec = sensors.get(name)
    if not isinstance(spec, dict) or not str(spec.get("type", "")).endswith("Camera"):
        cameras = [n for n, s in sensors.items() if str(s.get("type", "")).endswith("Camera")]
        raise ValueError(
            f"the robot has no camera {name!r} (cameras: {', '.join(cameras) or 'none'})"
        )
    width, height = spec.get("resolution") or (640, 480)
    return int(height), int(width), 3


class PoppyRobot(Robot):
    """A Poppy robot driven by poppy: a serial port, a served robot or the simulation."""

    config_class: type[Any] = PoppyFollowerFields
    name = "poppy"

    def __init__(self, config: Any) -> None:
        super().__init__(config)
        self.config = config
        self.poppy_config = with_camera_resolution(
            link.load_config(config.profile, self.name),
            config.robot_cameras,
            config.robot_camera_resolution,
        )
        self.joints = link.joints(self.poppy_config, config.group)
        self._robot_cameras = {n: camera_shape(self.poppy_config, n) for n in config.robot_cameras}
        self.cameras = make_cameras_from_configs(config.cameras)
        self._link: Any = None
        self._limits: dict[str, tuple[float, float] | None] = {}

    @cached_property
    def observation_features(self) -> dict[str, Any]:
        cameras = {name: (cfg.height, cfg.width, 3) for name, cfg in self.config.cameras.items()}
        return {**self.action_features, **self._robot_cameras, **cameras}

    @cached_property
    def action_features(self) -> dict[str, type]:
        return {f"{name}.pos": float for name in self.joints}

    @property
    def is_connected(self) -> bool:
        return self._link is not None and all(c.is_connected for c in self.cameras.values())

    @property
    def is_calibrated(self) -> bool:
        """A served robot is calibrated by its server; a local one once LeRobot's calibration
        file holds its joints."""
        if link.is_remote(self.config.port):
            return True
        return set(self.joints) <= set(self.calibration)

    def calibrate(self) -> None:
        """Write LeRobot's calibration file from poppy's config (its orientations, offsets and
        limits: what `poppy calibrate` measured into the profile given, or the shipped one).

        Moving the robot through its reference posture is `poppy calibrate`'s job; this keeps
        its result where LeRobot looks. A served robot: nothing to do (the server's config).
        """
        if link.is_remote(self.config.port):
            return
        self.calibration = {
            **self.calibration,
            **calibration.from_poppy(self.poppy_config, self.joints),
        }
        self._save_calibration()
        logger.info("calibration of %s written to %s", self, self.calibration_fpath)

    @check_if_already_connected
    def connect(self, calibrate: bool = True) -> None:
        if not self.is_calibrated and calibrate:
            self.calibrate()
        config = self.poppy_config
        if self.calibration and not link.is_remote(self.config.port):
            config = calibration.apply(config, self.calibration)
        self._limits = link.limits_of(config, self.joints)
        self._link = link.open_link(
            config,
            self.config.port,
            self.joints,
            list(self._robot_cameras),
            self.config.zenoh_connect,
        )
        try:
            for cam in self.cameras.values():
                cam.connect()
            self._first_frames()
            self.configure()
        except BaseException:
            self._link.close()
            self._link = None
            raise
        logger.info("%s connected on %s", self, self.config.port)

    def _first_frames(self) -> None:
        """Start the robot's cameras now (the first frame takes long: a camera opening, a
        renderer made), and check their frames have the shape announced."""
        for name, shape in self._robot_cameras.items():
            got = tuple(self._link.frame(name).shape)
            if got != shape:
                raise ValueError(
                    f"the robot's camera {name!r} gives {got[1]}x{got[0]} frames, not the "
                    f"{shape[1]}x{shape[0]} of its config: set robot_camera_resolution"
                )

    def configure(self) -> None:
        """Stiff joints, holding where they are (a compliant joint takes no goal)."""
        here = self._link.positions(self.joints)
        self._link.set_compliant(self.joints, False)
        self._link.send({n: link_clamp(v, self._limits[n]) for n, v in here.items()})

    @check_if_not_connected
    def get_observation(self) -> RobotObservation:
        positions = self._link.positions(self.joints)
        observation: dict[str, Any] = {f"{n}.pos": v for n, v in positions.items()}
        for name in self._robot_cameras:
            observation[name] = self._link.frame(name)
        for name, cam in self.cameras.items():
            observation[name] = cam.read_latest()
        return observation

    @check_if_not_connected
    def send_action(self, action: RobotAction) -> RobotAction:
        """Send the goals of ``action`` (``NAME.pos``, degrees): clamped to the joints' angle
        limits, then capped to ``max_relative_target`` from the present positions.

        Returns:
            The goals sent, ``NAME.pos`` each.
        """
        unknown = [k for k in action if k.removesuffix(".pos") not in self.joints]
        if unknown:
            raise ValueError(
                f"unknown action keys {', '.join(map(str, unknown))} "
                f"(keys: {', '.join(self.action_features)})"
            )
        goals = {
            k.removesuffix(".pos"): link_clamp(float(v), self._limits[k.removesuffix(".pos")])
            for k, v in action.items()
        }
        if self.config.max_relative_target is not None:
            present = self._link.positions(list(goals))
            goals = ensure_safe_goal_position(
                {n: (g, present[n]) for n, g in goals.items()}, self.config.max_relative_target
            )
        self._link.send(goals)
        return {f"{n}.pos": v for n, v in goals.items()}

    @check_if_not_connected
    def disconnect(self) -> None:
        try:
            if self.config.disable_torque_on_disconnect:
                self._link.set_compliant(self.joints, True)
            for cam in self.cameras.values():
                cam.disconnect()
        finally:
            self._link.close()
            self._link = None
        logger.info("%s disconnected", self)


def link_clamp(value: float, limits: tuple[float, float] | None) -> float:
    """Poppy's one limit rule (``poppy_core.trajectory.clamp_goal``)."""
    from poppy_core.trajectory import clamp_goal

    return clamp_goal(value, limits)


class PoppyErgoJr(PoppyRobot):
    """A Poppy Ergo Jr: six XL-320 (protocol 2), ``m1``...``m6``."""

    config_class = PoppyErgoJrConfig
    name = "poppy_ergo_jr"


class PoppyTorso(PoppyRobot):
    """A Poppy Torso: MX-28/MX-64/AX-12A (protocol 1)."""

    config_class = PoppyTorsoConfig
    name = "poppy_torso"


class PoppyHumanoid(PoppyRobot):
    """A Poppy Humanoid."""

    config_class = PoppyHumanoidConfig
    name = "poppy_humanoid"
