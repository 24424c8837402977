"""Config sections checked as a robot config checks them, for tests of the leaves they feed."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from poppy_core.robot import RobotConfig
from poppy_core.robot.config_sensors import sensor_specs
from poppy_core.sensors import SensorSpec


def checked_sensors(section: Mapping[str, Any]) -> list[SensorSpec]:
    """The sensors leaf's entries of a ``sensors`` section (a ConfigError lists its problems)."""
    config = RobotConfig.from_dict({"controllers": {}, "motors": {}, "sensors": dict(section)})
    return sensor_specs(config.sensors)
