"""pypot's Snap! server for poppy: plain-text routes, Poppy blocks and projects as Snap! XML.

Importing this package loads Starlette (the CLI imports it only inside ``poppy serve --snap``).
"""

from poppy_core.server.snap.blocks import RobotFacts
from poppy_core.server.snap.server import (
    DEFAULT_PORT,
    SnapServer,
    create_snap_server,
    robot_facts,
    snap_policy,
    start_snap_server,
)
from poppy_core.server.snap.site import SnapSite

__all__ = [
    "DEFAULT_PORT",
    "RobotFacts",
    "SnapServer",
    "SnapSite",
    "create_snap_server",
    "robot_facts",
    "snap_policy",
    "start_snap_server",
]
