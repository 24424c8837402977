"""The config's ``sensors`` section: pypot's form accepted, bad or unsupported sensors refused in
one line, and robots built with their sensors (``robot.sensors``, ``robot.camera``)."""

from __future__ import annotations

from typing import Any

import pytest

from poppy_core import from_profile
from poppy_core.errors import ConfigError
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.robot.config_sensors import sensor_specs
from poppy_core.sensors import DummyCamera, MarkerDetector

pytest.importorskip("cv2")


def with_sensors(sensors: dict[str, Any]) -> dict[str, Any]:
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"] = sensors
    return data


@pytest.mark.parametrize(
    ("kind", "name"),
    [("ForceSensor", "force")],
)
def test_sensors_not_built_yet_are_one_line_errors(kind: str, name: str) -> None:
    with pytest.raises(ConfigError) as caught:
        RobotConfig.from_dict(with_sensors({"thing": {"type": kind}}), source="robot.json")
    message = str(caught.value)
    assert message.startswith(f'robot.json: sensors.thing.type = "{kind}": ')
    assert f"{name} sensors are not supported yet" in message and "\n" not in message
    assert caught.value.field == "sensors.thing.type"


@pytest.mark.parametrize(
    ("sensors", "words"),
    [
        ({"cam": {"type": "WebCam"}}, 'sensors.cam.type = "WebCam": unknown sensor type'),
        ({"cam": {"type": "OpenCVCamera", "fps": 0}}, "sensors.cam.fps = 0: must be a positive"),
        ({"cam": {"type": "OpenCVCamera", "resolution": [640]}}, "resolution = [640]: must be"),
        ({"cam": {"type": "OpenCVCamera", "calibration": {"camera_matrix": [1]}}}, "calibration"),
        ({"md": {"type": "MarkerDetector", "cameras": ["cam"]}}, "'cam' is not a camera here"),
        (
            {
                "cam": {"type": "DummyCamera"},
                "md": {"type": "MarkerDetector", "cameras": ["cam"], "cards": {"caribou": "x"}},
            },
            "sensors.md.cards.caribou",
        ),
        ({"m1": {"type": "DummyCamera"}}, "sensor 'm1' has the name of a motor or group"),
        ({"cam": "OpenCVCamera"}, 'sensors.cam = "OpenCVCamera": must be a valid dictionary'),
        ({"a": {"type": "ArduinoSensor"}}, "ArduinoSensor needs its 'port' key"),
        ({"a": {"type": "ArduinoSensor", "port": "/dev/ttyACM0", "baud": 0}}, "baud = 0: must"),
        ({"c": {"type": "ContactSensor"}}, "ContactSensor needs its 'gpio_data' key"),
        ({"s": {"type": "SonarSensor", "address": 112}}, "SonarSensor needs its 'i2c_pin' key"),
        (
            {"s": {"type": "SonarSensor", "i2c_pin": 1, "address": 224}},
            "sensors.s.address = 224: must be a 7-bit I2C address (112 is 0x70)",
        ),
    ],
)
def test_bad_sensor_entries_are_one_line_errors(sensors: dict[str, Any], words: str) -> None:
    with pytest.raises(ConfigError) as caught:
        RobotConfig.from_dict(with_sensors(sensors), source="robot.json")
    assert words in str(caught.value) and "\n" not in str(caught.value)


def test_pypot_device_sensor_entries_load_with_pypots_keys() -> None:
    sensors = {
        "arduino": {"type": "ArduinoSensor", "port": "/dev/ttyACM0", "baud": 1000000},
        "bumper": {"type": "ContactSensor", "gpio_data": 17, "gpio_vcc": 27},
        "sonar": {"type": "SonarSensor", "i2c_pin": 1, "address": 112, "sync_freq": 10.0},
    }
    config = RobotConfig.from_dict(with_sensors(sensors), source="robot.json")
    specs = {spec.name: spec for spec in sensor_specs(config.sensors)}
    assert (specs["arduino"].port, specs["arduino"].baud) == ("/dev/ttyACM0", 1000000)
    assert (specs["bumper"].gpio_data, specs["bumper"].gpio_vcc) == (17, 27)
    assert (specs["sonar"].i2c_pin, specs["sonar"].address, specs["sonar"].rate_hz) == (1, 112, 10)
    assert config.to_pypot_dict()["sensors"] == sensors


def test_pypot_sections_load_and_round_trip() -> None:
    sensors = {
        "camera": {"type": "OpenCVCamera", "index": -1, "fps": 20.0, "resolution": [640, 480]},
        "marker_detector": {
            "type": "MarkerDetector",
            "cameras": ["camera"],
            "freq": 1.0,
            "need_robot": True,
        },
    }
    config = RobotConfig.from_dict(with_sensors(sensors))
    assert config.to_pypot_dict()["sensors"] == sensors


def test_a_simulated_robot_has_the_profiles_sensors() -> None:
    with from_profile("ergo-jr", sim=True) as robot:
        assert [s.name for s in robot.sensors] == ["camera", "marker_detector"]
        camera = robot.camera
        assert isinstance(camera, DummyCamera) and robot.sensor("camera") is camera
        assert camera.registers == ("frame", "resolution", "fps")
        assert camera.resolution == [640, 480] and camera.fps == 20.0
        detector = robot.marker_detector
        assert isinstance(detector, MarkerDetector) and detector.cameras == [camera]
        assert detector.card_ids == {
            "caribou": [221052793],
            "tetris": [112259237],
            "lapin": [44616414],
        }
        assert detector.sees("tetris") is False
        assert set(robot.sensor_health()) == {"camera", "marker_detector"}
        assert "camera" in dir(robot)
        with pytest.raises(ConfigError, match=r"no sensor 'lidar' \(sensors: camera, marker_"):
            robot.sensor("lidar")
    assert camera.closed and detector.closed and not camera.running


def test_sensors_can_be_left_out() -> None:
    with from_profile("ergo-jr", sim=True, sensors=False) as robot:
        assert robot.sensors == []
        with pytest.raises(AttributeError, match="no motor, group, sensor or attribute"):
            _ = robot.camera


def test_a_missing_camera_does_not_stop_a_real_robot(tmp_path: Any) -> None:
    data = with_sensors({"camera": {"type": "OpenCVCamera", "index": "/dev/video99"}})
    data["controllers"]["my_dxl_controller"]["port"] = "loop://"
    from poppy_core import from_config

    with from_config(RobotConfig.from_dict(data), strict=False) as robot:
        health = robot.sensor_health()["camera"]
        assert not health.connected
        assert health.last_error == (
            "/dev/video99 does not exist: plug the camera in (`poppy camera list` shows them)"
        )
