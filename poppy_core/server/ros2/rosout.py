"""Refusals where ROS 2 users look: ``/rosout`` (``rcl_interfaces/msg/Log``, what ``ros2 topic
echo /rosout`` and rqt_console show) and a ``commands`` status in ``/diagnostics``.

The node's other logs stay in Python's logging; a command or service call it refuses is also
published here, at WARN, with the node's fully qualified name as the logger's, as an rclcpp
node's ``RCLCPP_WARN`` would be.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from poppy_core.ros2_wire import TRANSIENT_LOCAL, Qos
from poppy_core.server.ros2 import types
from poppy_core.server.ros2.messages import stamp

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


class Refusals:
    """The refusals of a node: counted, the last one kept for ``/diagnostics``."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.count = 0
        self.last = ""
        self._at = -RECENT_S

    def add(self, text: str) -> None:
        with self._lock:
            self.count += 1
            self.last = text
            self._at = time.monotonic()

    def status(self, node: str) -> Any:
        """A ``DiagnosticStatus`` named ``NODE: commands``: WARN with the last refusal for
        ``RECENT_S`` after it, else OK; the count and the last refusal as values."""
        with self._lock:
            recent = time.monotonic() - self._at < RECENT_S
            count, last = self.count, self.last
        values = [
            types.message("diagnostic_msgs/msg/KeyValue", key="refused", value=str(count)),
            types.message("diagnostic_msgs/msg/KeyValue", key="last_refusal", value=last),
        ]
        return types.message(
            "diagnostic_msgs/msg/DiagnosticStatus",
            level=1 if recent else 0,
            name=f"{node}: commands",
            message=f"refused: {last}" if recent else "ok",
            hardware_id=node,
            values=values,
        )
