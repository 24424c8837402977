"""Run inside LeRobot's venv with the plugin installed: what LeRobot makes of the Poppy types.

``python plugin_probe.py contract FOLLOWER_PORT LEADER_PORT``: the types LeRobot's registries
hold after ``register_third_party_plugins``, the features while disconnected, and a follower
and a leader driven through LeRobot's factories on the ports given (the test's emulators).
``python plugin_probe.py served URL``: a follower on a robot `poppy serve` serves.
``python plugin_probe.py served_camera URL``: the same follower observing the robot's camera.
``python plugin_probe.py zenoh NAME ENDPOINT``: a follower, then a leader, on the robot served
on Zenoh as ``poppy/NAME``, listening on ENDPOINT.
``python plugin_probe.py bodies TORSO_PORT HUMANOID_PORTS``: a Torso and a Humanoid
(``CONTROLLER=PORT,...``) connected, observed and sent an action.
One JSON object on stdout. ``python plugin_probe.py serve``: the same commands, asked one JSON
line each on stdin (tests/helpers/json_lines.py), in one process for the test session.
"""

from __future__ import annotations

import json
import sys
from typing import Any


def contract(follower_port: str, leader_port: str) -> dict[str, Any]:
    from lerobot.robots import RobotConfig, make_robot_from_config
    from lerobot.teleoperators import TeleoperatorConfig, make_teleoperator_from_config
    from lerobot.utils.constants import HF_LEROBOT_CALIBRATION
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
    out: dict[str, Any] = {
        "robots": sorted(k for k in RobotConfig.get_known_choices() if k.startswith("poppy")),
        "teleops": sorted(
            k for k in TeleoperatorConfig.get_known_choices() if k.startswith("poppy")
        ),
        "calibration_root": str(HF_LEROBOT_CALIBRATION),
    }
    features = {}
    for kind in out["robots"]:
        robot = make_robot_from_config(RobotConfig.get_choice_class(kind)(port="sim", id="x"))
        features[kind] = {
            "class": type(robot).__name__,
            "observation": list(robot.observation_features),
            "action": list(robot.action_features),
            "connected": robot.is_connected,
        }
    for kind in out["teleops"]:
        teleop = make_teleoperator_from_config(
            TeleoperatorConfig.get_choice_class(kind)(port="sim", id="x")
        )
        features[kind] = {"class": type(teleop).__name__, "action": list(teleop.action_features)}
    camera = RobotConfig.get_choice_class("poppy_ergo_jr")(
        port="sim", id="x", robot_cameras=["camera"], robot_camera_resolution=[64, 48]
    )
    features["with_camera"] = make_robot_from_config(camera).observation_features["camera"]
    out["features"] = features
    out["help"] = field_help(
        RobotConfig.get_choice_class("poppy_ergo_jr"),
        TeleoperatorConfig.get_choice_class("poppy_ergo_jr_leader"),
    )

    config = RobotConfig.get_choice_class("poppy_ergo_jr")
    follower = make_robot_from_config(
        # an id no other test connects: its calibration file is written by this first connect
        config(port=follower_port, id="contract-follower", disable_torque_on_disconnect=False)
    )
    out["calibrated_before"] = follower.is_calibrated
    follower.connect()
    out["calibrated_after"] = follower.is_calibrated
    out["calibration_file"] = str(follower.calibration_fpath)
    out["observation"] = follower.get_observation()
    out["sent_beyond_limits"] = follower.send_action({"m1.pos": 500.0, "m3.pos": -500.0})
    follower.config.max_relative_target = 5.0
    here = follower.get_observation()["m4.pos"]
    out["sent_capped"] = follower.send_action({"m4.pos": here + 40.0})
    out["present_m4"] = here
    try:
        follower.send_action({"m9.pos": 0.0})
    except ValueError as exc:
        out["unknown_key"] = str(exc)
    follower.disconnect()
    out["connected_after_disconnect"] = follower.is_connected

    leader_config = TeleoperatorConfig.get_choice_class("poppy_ergo_jr_leader")
    leader = make_teleoperator_from_config(leader_config(port=leader_port, id="leader"))
    leader.connect()
    out["leader_calibrated"] = leader.is_calibrated
    out["leader_action"] = leader.get_action()
    leader.disconnect()
    return out


def field_help(*configs: type) -> dict[str, dict[str, str | None]]:
    """Each config field's help as LeRobot's parser (draccus) finds it for ``--help``."""
    from dataclasses import fields

    from draccus.wrappers.docstring import get_attribute_docstring, get_preferred_help_text

    return {
        config.__name__: {
            f.name: get_preferred_help_text(get_attribute_docstring(config, f.name))
            for f in fields(config)
        }
        for config in configs
    }


def served(url: str) -> dict[str, Any]:
    """A follower on a robot served by `poppy serve --http` (``url``)."""
    from lerobot.robots import RobotConfig, make_robot_from_config
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
    config = RobotConfig.get_choice_class("poppy_ergo_jr")(port=url, id="served")
    robot = make_robot_from_config(config)
    robot.connect()
    out: dict[str, Any] = {"calibrated": robot.is_calibrated}
    out["observation"] = robot.get_observation()
    out["sent"] = robot.send_action({"m1.pos": 500.0, "m2.pos": 20.0})
    robot.disconnect()
    return out


def served_camera(url: str) -> dict[str, Any]:
    """A follower on a robot `poppy serve` serves, observing the robot's own camera."""
    from lerobot.robots import RobotConfig, make_robot_from_config
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
    config = RobotConfig.get_choice_class("poppy_ergo_jr")
    robot = make_robot_from_config(config(port=url, id="served-camera", robot_cameras=["camera"]))
    out: dict[str, Any] = {
        "features": {
            k: list(v) for k, v in robot.observation_features.items() if isinstance(v, tuple)
        }
    }
    robot.connect()
    image = robot.get_observation()["camera"]
    out["shape"] = list(image.shape)
    out["dtype"] = str(image.dtype)
    out["pixels"] = {f"{y},{x}": image[y, x].tolist() for y, x in ((0, 0), (10, 200), (300, 600))}
    robot.disconnect()
    return out


def zenoh(name: str, endpoint: str) -> dict[str, Any]:
    """A follower, then a leader, on ``zenoh:NAME`` reached at ``endpoint`` only."""
    import time

    from lerobot.robots import RobotConfig, make_robot_from_config
    from lerobot.teleoperators import TeleoperatorConfig, make_teleoperator_from_config
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
    port, connect = f"zenoh:{name}", [endpoint]
    config = RobotConfig.get_choice_class("poppy_ergo_jr")
    robot = make_robot_from_config(config(port=port, zenoh_connect=connect, id="zenoh"))
    robot.connect()
    out: dict[str, Any] = {"calibrated": robot.is_calibrated}
    out["observation"] = robot.get_observation()
    out["sent"] = robot.send_action({"m1.pos": 500.0, "m2.pos": 20.0})
    # the served robot moves to the goals: seen in the observations (generous: a busy machine)
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        seen = robot.get_observation()
        if abs(seen["m1.pos"] - 150.0) < 2.0 and abs(seen["m2.pos"] - 20.0) < 2.0:
            break
        time.sleep(0.05)
    out["reached"] = seen
    robot.disconnect()
    leader_config = TeleoperatorConfig.get_choice_class("poppy_ergo_jr_leader")
    leader = make_teleoperator_from_config(
        leader_config(port=port, zenoh_connect=connect, id="zenoh-leader")
    )
    leader.connect()
    out["leader_action"] = leader.get_action()
    leader.disconnect()
    return out


def bodies(torso_port: str, humanoid_ports: str) -> dict[str, Any]:
    """A Torso on ``torso_port`` and a Humanoid on ``humanoid_ports`` (one per bus): keys, an
    action, read back."""
    import time

    from lerobot.robots import RobotConfig, make_robot_from_config
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
    out: dict[str, Any] = {}
    for kind, port, action in (
        ("poppy_torso", torso_port, {"l_elbow_y.pos": -40.0, "head_z.pos": 20.0}),
        ("poppy_humanoid", humanoid_ports, {"r_elbow_y.pos": -40.0, "l_knee_y.pos": 30.0}),
    ):
        config = RobotConfig.get_choice_class(kind)
        robot = make_robot_from_config(config(port=port, id=kind))
        robot.connect()
        observation = robot.get_observation()
        sent = robot.send_action(action)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            reached = robot.get_observation()
            if all(abs(reached[k] - v) < 2.0 for k, v in sent.items()):
                break
            time.sleep(0.05)
        out[kind] = {
            "features": list(robot.observation_features),
            "observation": list(observation),
            "sent": sent,
            "reached": {k: reached[k] for k in sent},
            "calibration": {k: vars(v) for k, v in robot.calibration.items()},
        }
        robot.disconnect()
    refused = {}
    for port in ("/dev/ttyUSB0", "upper_body_controller=/dev/ttyUSB0,legs=/dev/ttyUSB1"):
        robot = make_robot_from_config(RobotConfig.get_choice_class("poppy_humanoid")(port=port))
        try:
            robot.connect()
        except ValueError as exc:
            refused[port] = str(exc)
    out["refused"] = refused
    return out


def warm() -> None:
    """LeRobot's factories imported and the plugin registered: most of a command's CPU."""
    import lerobot.robots
    import lerobot.teleoperators  # noqa: F401
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()


def load_serve() -> Any:
    """tests/helpers/json_lines.py's ``serve``, loaded by its path (the venv has a ``tests``)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "helpers" / "json_lines.py"
    spec = importlib.util.spec_from_file_location("poppy_json_lines", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.serve


if __name__ == "__main__":
    commands = {
        "contract": contract,
        "served": served,
        "served_camera": served_camera,
        "zenoh": zenoh,
        "bodies": bodies,
    }
    if sys.argv[1] == "serve":
        load_serve()(commands, warm)
    else:
        result = commands[sys.argv[1]](*sys.argv[2:])
        sys.stdout.write(json.dumps(result) + "\n")
