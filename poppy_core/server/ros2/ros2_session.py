"""The Zenoh session of a set that serves ROS 2: the fleet's settings, with timestamps on.

rmw_zenoh's sessions stamp every sample (its default session config enables ``timestamping``)
and its transient-local topics are Zenoh advanced publishers, which need those stamps.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from poppy_core.zenoh_wire import ZenohSettings, open_session, session_config

if TYPE_CHECKING:
    import zenoh


def open_ros2_session(settings: ZenohSettings) -> zenoh.Session:
    """A session joined as ``settings`` say, stamping its samples; a client's waits for its
    router (``open_session``).

    Raises:
        ConfigError: a bad configuration, or an endpoint Zenoh cannot listen on or reach.
        MissingExtraError: eclipse-zenoh is not installed.
    """
    config = session_config(settings)
    config.insert_json5("timestamping/enabled", "true")
    return open_session(settings, wait_s=None, config=config)
