"""The REST/WebSocket server over a ``Robot``: pypot's routes, the v1 API and a state stream.

Importing this package loads FastAPI: the CLI imports it only inside ``poppy serve``. Without
the ``server`` extra, importing it raises ``MissingExtraError`` naming the extra.
"""

from poppy_core.server import needs  # noqa: F401  (checks the server extra, before the rest)
from poppy_core.server.app import create_app
from poppy_core.server.errors import ListenError
from poppy_core.server.origin_guard import OriginGuard
from poppy_core.server.origins import OriginPolicy
from poppy_core.server.runner import ServerThread, bind_sockets, uvicorn_server
from poppy_core.server.service import RobotService
from poppy_core.server.stream import create_stream_app
from poppy_core.server.zmqserver import ZMQRobotServer, ZmqRobotServer

__all__ = [
    "ListenError",
    "OriginGuard",
    "OriginPolicy",
    "RobotService",
    "ServerThread",
    "ZMQRobotServer",
    "ZmqRobotServer",
    "bind_sockets",
    "create_app",
    "create_stream_app",
    "uvicorn_server",
]
