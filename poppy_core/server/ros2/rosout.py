"""Refusals where ROS 2 users look: ``/rosout`` (``rcl_interfaces/msg/Log``, what ``ros2 topic
echo /rosout`` and rqt_console show) and a ``commands`` status in ``/diagnostics``.

The node's other logs stay in Python's logging; a command or service call it refuses is also
published here, at WARN, with the node's fully qualified name as the logger's, as an rclcpp
node's ``RCLCPP_WARN`` would be.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from poppy_core.ros2_wire import TRANSIENT_LOCAL, Qos
from poppy_core.server.ros2 import types
from poppy_core.server.ros2.messages import stamp
from poppy_core.server.ros2.refusal_log import LOG_EVERY_S, Refusal, Refusals

LOG = "rcl_interfaces/msg/Log"
WARN = 30
"""``rcl_interfaces/msg/Log``'s WARN level."""
ROSOUT_QOS = Qos(durability=TRANSIENT_LOCAL, depth=1000)
"""rcl's ``/rosout`` publisher QoS (keep last 1000, reliable, transient local; its 10 s
lifespan is not declared, as rmw_zenoh enforces none)."""
RECENT_S = 60.0
"""How long the ``commands`` status stays WARN after a refusal."""


def log_message(logger: str, level: int, text: str, function: str, now: float | None = None) -> Any:
    """One ``rcl_interfaces/msg/Log``: ``logger`` the node's name, without its leading slash."""
    return types.message(
        LOG,
        stamp=stamp(now),
        level=level,
        name=logger.lstrip("/").replace("/", "."),
        msg=text,
        file=__name__,
        function=function,
        line=0,
    )


class RosoutRefusals:
    """A ``Refusals`` listener that publishes each refusal on ``/rosout``: a service's each time,
    a topic's one a second at most, whatever the rate (as the log does).

    Args:
        publish: ``publish(text, function)`` puts one WARN line on ``/rosout``.
    """

    def __init__(self, publish: Callable[[str, str], None]) -> None:
        self._publish = publish
        self._lock = threading.Lock()
        self._last_topic = -LOG_EVERY_S

    def publish(self, refusal: Refusal) -> None:
        if refusal.kind == "topic":
            now = time.monotonic()
            with self._lock:
                if now - self._last_topic <= LOG_EVERY_S:
                    return
                self._last_topic = now
            self._publish(
                f"{refusal.where} refused, nothing moved: {refusal.reason}", "subscription"
            )
        else:
            self._publish(f"{refusal.where} refused: {refusal.reason}", "service")


def commands_status(refusals: Refusals, node: str) -> Any:
    """A ``DiagnosticStatus`` named ``NODE: commands``: WARN with the last refusal for
    ``RECENT_S`` after it, else OK; the count and the last refusal as values."""
    last = refusals.last
    recent = last is not None and time.time() - last.stamp < RECENT_S
    text = f"{last.where} refused, nothing moved: {last.reason}" if last is not None else ""
    values = [
        types.message("diagnostic_msgs/msg/KeyValue", key="refused", value=str(refusals.count)),
        types.message("diagnostic_msgs/msg/KeyValue", key="last_refusal", value=text),
    ]
    return types.message(
        "diagnostic_msgs/msg/DiagnosticStatus",
        level=1 if recent else 0,
        name=f"{node}: commands",
        message=f"refused: {text}" if recent else "ok",
        hardware_id=node,
        values=values,
    )
