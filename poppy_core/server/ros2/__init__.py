"""The robot as a ROS 2 node over rmw_zenoh's wire, with no ROS installed (``poppy serve --ros2``).

``wire`` holds rmw_zenoh's keys, tokens and attachments; ``types`` the messages (rosbags: CDR
and RIHS01 hashes); ``node`` the node itself. Needs the ``ros2`` extra (rosbags, eclipse-zenoh).
"""

from poppy_core.ros2_wire import Ros2Settings
from poppy_core.server.ros2.node import Ros2Node

__all__ = ["Ros2Node", "Ros2Settings"]
