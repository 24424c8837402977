"""`poppy serve --ros2` publishes each IMU as sensor_msgs/Imu on ``<name>/data``."""

from __future__ import annotations

import math

import pytest

pytest.importorskip("zenoh")
pytest.importorskip("rosbags")

from poppy_core import from_config
from poppy_core.assembly import ServeSpec, serve
from poppy_core.robot import RobotConfig, load_profile
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.waiting import eventually
from tests.ros2.rmw_client import Collector
from tests.ros2.test_ros2_node import client_session, free_endpoint

IMU = "sensor_msgs/msg/Imu"


def test_an_imu_is_published_with_what_it_measures() -> None:
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"] = {"imu": {"type": "RazorIMU", "port": "/dev/ttyUSB9"}}
    endpoint = free_endpoint()
    with from_config(RobotConfig.from_dict(data), sim=True) as robot:
        settings = Ros2Settings(zenoh=ZenohSettings(listen=(endpoint,)))
        servers = serve(robot, ServeSpec(ros2=settings, name="jr1"))
        session = client_session(endpoint)
        readings = Collector(session, 0, "/imu/data", IMU)
        try:
            assert eventually(lambda: len(readings.snapshot()) >= 2, 20.0)
            message = readings.snapshot()[-1][1]
        finally:
            readings.close()
            session.close()
            servers.stop()
    assert message.header.frame_id == "imu" and message.header.stamp.sec > 0
    q = message.orientation
    assert (q.w, q.x, q.y, q.z) == (1.0, 0.0, 0.0, 0.0)  # the ideal robot's IMU: level
    assert math.isclose(message.linear_acceleration.z, 9.80665, abs_tol=1e-3)
    assert message.angular_velocity_covariance[0] == 0.0  # measured (-1 would say it is not)
