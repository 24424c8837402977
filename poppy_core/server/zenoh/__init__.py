"""The robot on Zenoh (``poppy serve --zenoh``): its node under ``poppy/NAME``, the REST app
answering Zenoh queries in-process. The keys and the state message are ``poppy_core.zenoh_wire``."""

from poppy_core.server.zenoh.robot_node import ZenohRobotServer

__all__ = ["ZenohRobotServer"]
