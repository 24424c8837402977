"""The LeRobot config types of Poppy robots and leaders (`--robot.type=poppy_ergo_jr`...)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.cameras import CameraConfig
from lerobot.robots import RobotConfig
from lerobot.teleoperators import TeleoperatorConfig


@dataclass(kw_only=True)
class PoppyFields:
    """What a Poppy robot or leader is reached through (both config kinds share it)."""

    # Where the robot is: a serial port (/dev/ttyUSB0, or a pyserial URL; a robot of several
    # buses, the Humanoid: `upper_body_controller=/dev/ttyUSB0,lower_body_controller=...`),
    # `http://HOST:PORT`
    # of `poppy serve --http`, `zenoh:NAME` of `poppy serve --zenoh --name NAME`, `sim` (the
    # MuJoCo simulation of `poppy sim`) or `sim:ideal` (ideal servos, no physics).
    port: str
    # A poppy profile name or config file (a user profile made by `poppy calibrate`, say);
    # empty: the type's own profile (ergo-jr, torso, humanoid).
    profile: str = ""
    # Only the joints of this motor group (`l_arm`, `arms`...); empty: every joint.
    group: str = ""
    # `zenoh:NAME` only: the Zenoh endpoints to connect to (`[tcp/192.168.1.20:7447]`, the
    # robot's `--zenoh-listen` or a router); empty: POPPY_ZENOH_CONNECT, else
    # tcp/127.0.0.1:7447. Scouting stays off.
    zenoh_connect: list[str] = field(default_factory=list)


@dataclass(kw_only=True)
class PoppyFollowerFields(PoppyFields):
    """A follower's fields: cameras, safety, torque."""

    # LeRobot's cameras (OpenCV, RealSense...), each observed as `NAME` (H, W, 3) RGB.
    cameras: dict[str, CameraConfig] = field(default_factory=dict)
    # The robot's own cameras (the profile's `sensors`, e.g. the Ergo Jr's `camera`); under
    # `sim` they are rendered by MuJoCo from where the real one sits; on a served robot they are
    # the server's (its `frame.png` route, over HTTP or Zenoh).
    robot_cameras: list[str] = field(default_factory=list)
    # [width, height] of the robot's own cameras (a small one for a policy on a CPU, say);
    # empty: the profile's (640x480 on the Ergo Jr).
    robot_camera_resolution: list[int] = field(default_factory=list)
    # The largest step from the present position a goal may ask (degrees; one number or
    # motor -> number); None: no cap. Goals are always clamped to the joints' angle limits.
    max_relative_target: float | dict[str, float] | None = None
    # Torque off (compliant) when LeRobot disconnects; False leaves the motors stiff.
    disable_torque_on_disconnect: bool = True


# The fields' class is the first base: LeRobot's parser (draccus) looks a field's `--help` up
# in the class's source, then its first base's, and so on; RobotConfig first, it never found the
# Poppy fields' comments and re-parsed typing.py for each (seconds of CPU a command start).
@RobotConfig.register_subclass("poppy_ergo_jr")
@dataclass(kw_only=True)
class PoppyErgoJrConfig(PoppyFollowerFields, RobotConfig):
    """A Poppy Ergo Jr (6 XL-320) as a LeRobot robot."""


@RobotConfig.register_subclass("poppy_torso")
@dataclass(kw_only=True)
class PoppyTorsoConfig(PoppyFollowerFields, RobotConfig):
    """A Poppy Torso (MX-28/MX-64/AX-12A) as a LeRobot robot."""


@RobotConfig.register_subclass("poppy_humanoid")
@dataclass(kw_only=True)
class PoppyHumanoidConfig(PoppyFollowerFields, RobotConfig):
    """A Poppy Humanoid as a LeRobot robot."""


@dataclass(kw_only=True)
class PoppyLeaderFields(PoppyFields):
    """A leader's fields."""

    # A primitive of the leader (`dance`...) moves it instead of a hand: what a simulated
    # leader, moved by nobody, needs to give demonstrations. Empty: the leader turns
    # compliant and is moved by hand.
    primitive: str = ""


@TeleoperatorConfig.register_subclass("poppy_ergo_jr_leader")
@dataclass(kw_only=True)
class PoppyErgoJrLeaderConfig(PoppyLeaderFields, TeleoperatorConfig):
    """An Ergo Jr moved by hand, leading a `poppy_ergo_jr` follower."""


@TeleoperatorConfig.register_subclass("poppy_torso_leader")
@dataclass(kw_only=True)
class PoppyTorsoLeaderConfig(PoppyLeaderFields, TeleoperatorConfig):
    """A Torso's arms moved by hand, leading a `poppy_torso` follower."""

    group: str = "arms"


@TeleoperatorConfig.register_subclass("poppy_humanoid_leader")
@dataclass(kw_only=True)
class PoppyHumanoidLeaderConfig(PoppyLeaderFields, TeleoperatorConfig):
    """A Humanoid's arms moved by hand, leading a `poppy_humanoid` follower."""

    group: str = "arms"
