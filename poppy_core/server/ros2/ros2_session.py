"""The Zenoh session of a set that serves ROS 2: the fleet's settings, with timestamps on.

rmw_zenoh's sessions stamp every sample (its default session config enables ``timestamping``)
and its transient-local topics are Zenoh advanced publishers, which need those stamps.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from poppy_core.errors import ConfigError
from poppy_core.zenoh_wire import ZenohSettings, session_config

if TYPE_CHECKING:
    import zenoh


def open_ros2_session(settings: ZenohSettings) -> zenoh.Session:
    """A session joined as ``settings`` say, stamping its samples.

    Raises:
        ConfigError: a bad configuration, or an endpoint Zenoh cannot listen on or reach.
        MissingExtraError: eclipse-zenoh is not installed.
    """
    config = session_config(settings)
    import zenoh

    try:
        config.insert_json5("timestamping/enabled", "true")
        return zenoh.open(config)
    except zenoh.ZError as exc:
        raise ConfigError(
            f"cannot open the Zenoh session ({exc}): check --zenoh-listen / --zenoh-connect",
            field="zenoh",
        ) from None
