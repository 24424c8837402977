"""Generated valid configs survive dict, JSON and YAML round trips unchanged."""

from __future__ import annotations

import json
from typing import Any

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from poppy_core.models import ALL_MODELS
from poppy_core.robot import RobotConfig, config_to_text

NAMES = st.from_regex(r"[a-z][a-z0-9_]{0,7}", fullmatch=True)
FINITE = st.floats(min_value=-360, max_value=360, allow_nan=False) | st.integers(-360, 360)
JSON_SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(-(2**40), 2**40)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=12)
)
SENSOR_KEYS = {
    "type",
    "fps",
    "freq",
    "resolution",
    "calibration",
    "cameras",
    "cards",
    "marker_size",
    "families",
    "index",
    "device",
    "sim_camera",
}
JSON_VALUES = st.recursive(
    JSON_SCALARS,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(NAMES, inner, max_size=3),
    max_leaves=8,
)


def _model_names(protocol: int) -> list[str]:
    return sorted({m.name for m in ALL_MODELS if m.protocol == protocol})


@st.composite
def motor(draw: st.DrawFn, motor_id: int, protocol: int) -> dict[str, Any]:
    low, high = sorted(draw(st.lists(FINITE, min_size=2, max_size=2, unique_by=float)), key=float)
    data: dict[str, Any] = {
        "id": motor_id,
        "type": draw(st.sampled_from(_model_names(protocol))),
        "orientation": draw(st.sampled_from(["direct", "indirect"])),
        "offset": draw(FINITE),
        "angle_limit": [low, high],
    }
    if draw(st.booleans()):
        data["return_delay_time"] = draw(st.integers(0, 508))
        data["max_torque"] = draw(st.floats(0, 100))
        data["pid"] = draw(st.lists(st.floats(0, 64), min_size=3, max_size=3))
        data["wheel_mode"] = draw(st.booleans())
    if draw(st.booleans()):
        data["broken"] = draw(st.booleans())
    return data


@st.composite
def robot_configs(draw: st.DrawFn) -> dict[str, Any]:
    names = draw(st.lists(NAMES, min_size=2, max_size=16, unique=True))
    n_controllers = draw(st.integers(1, 3))
    controller_names = [f"bus_{i}" for i in range(n_controllers)]
    motor_names = [n for n in names if not n.startswith(("bus_", "group_", "outer_"))]
    controllers: dict[str, Any] = {}
    motors: dict[str, Any] = {}
    groups: dict[str, list[str]] = {}
    for index, cname in enumerate(controller_names):
        protocol = draw(st.sampled_from([1, 2]))
        mine = motor_names[index::n_controllers]
        top_id = 253 if protocol == 1 else 252  # e-manual: protocol 2 reserves 253 (0xFD)
        ids = draw(
            st.lists(st.integers(0, top_id), min_size=len(mine), max_size=len(mine), unique=True)
        )
        for name, motor_id in zip(mine, ids, strict=True):
            motors[name] = draw(motor(motor_id, protocol))
        attached: list[str] = list(mine)
        if len(mine) >= 2 and draw(st.booleans()):
            group = f"group_{index}"
            groups[group] = mine[:2]
            groups[f"outer_{index}"] = [group]
            attached = [f"outer_{index}", *mine[2:]]
        controller: dict[str, Any] = {
            "port": draw(st.sampled_from(["auto", "/dev/ttyUSB0", "socket://127.0.0.1:9000"])),
            "sync_read": draw(st.booleans()),
            "attached_motors": attached,
        }
        if protocol == 2 or draw(st.booleans()):
            controller["protocol"] = protocol
        if draw(st.booleans()):
            controller["baudrate"] = draw(st.sampled_from([57_600, 1_000_000, 3_000_000]))
            controller["syncloop"] = draw(
                st.sampled_from(["BaseDxlController", "LightDxlController"])
            )
        controllers[cname] = controller
    data: dict[str, Any] = {"controllers": controllers, "motorgroups": groups, "motors": motors}
    if draw(st.booleans()):
        # sensors of the types poppy builds, with any extra keys (kept as they are)
        extras = st.dictionaries(
            NAMES.filter(lambda n: n not in SENSOR_KEYS), JSON_VALUES, max_size=3
        )
        free = NAMES.filter(lambda n: n not in data["motors"] and n not in groups)
        cameras = draw(st.dictionaries(free, extras, max_size=2))
        data["sensors"] = {
            name: {"type": draw(st.sampled_from(["OpenCVCamera", "DummyCamera"])), **extra}
            for name, extra in cameras.items()
        }
    if draw(st.booleans()):
        data["x_extra"] = draw(JSON_VALUES)
    return data


# Hypothesis's default number of examples (tests/conftest.py: ten times as many when thorough)
@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(robot_configs())
def test_round_trips(data: dict[str, Any]) -> None:
    config = RobotConfig.from_dict(data, source="generated")
    assert config.to_pypot_dict() == data
    assert RobotConfig.from_dict(json.loads(config_to_text(config, "json"))) == config
    from_yaml = RobotConfig.from_dict(yaml.safe_load(config_to_text(config, "yaml")))
    assert from_yaml == config
    assert from_yaml.to_pypot_dict() == data
    for cname, controller in config.controllers.items():
        ids = [config.motors[m].id for m in config.motors_of_controller(cname)]
        assert len(ids) == len(set(ids))
        assert set(config.motors_of_controller(cname)) >= set(controller.attached_motors) - set(
            config.motorgroups
        )
    assert config.unattached_motors() == []
