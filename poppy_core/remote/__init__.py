"""A robot served by ``poppy serve --http``, driven from another process or machine.

``RemoteRobot("http://127.0.0.1:8080")`` mirrors ``Robot``: motors and groups as attributes,
registers as attributes of the motors, ``goto_position``, ``compliant``, primitives and moves.
It speaks the server's ``/api/v1`` with the standard library only (keep-alive connections);
``RemoteFollower`` drives it as a teleoperation follower over its WebSocket (``websockets``).
"""

from poppy_core.remote.client import HttpClient
from poppy_core.remote.remote_motion import RemoteMoves, RemotePrimitive
from poppy_core.remote.remote_robot import ModelInfo, RemoteGoto, RemoteMotor, RemoteRobot
from poppy_core.remote.teleop_follower import RemoteFollower

__all__ = [
    "HttpClient",
    "ModelInfo",
    "RemoteFollower",
    "RemoteGoto",
    "RemoteMotor",
    "RemoteMoves",
    "RemotePrimitive",
    "RemoteRobot",
]
