"""The servers a creature class starts (``use_http``, ``use_ws``, ``use_zmq``, ``use_snap``).

The one module of ``creatures`` that reaches the server room, and only inside functions: pypot's
creature constructors start servers, so ``PoppyErgoJr(use_http=True)`` must too. Each server is
attached to the robot under pypot's name (``robot.http``, ``robot.snap``...) and stopped by
``robot.close()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from poppy_core.errors import ConfigError

if TYPE_CHECKING:
    from poppy_core.robot import Robot


@dataclass(frozen=True)
class ServiceRequest:
    """One server a creature class was asked for: pypot's attribute name, address, port."""

    name: str
    host: str
    port: int


def _start(robot: Robot, request: ServiceRequest, start: bool) -> Any:
    if request.name == "http":
        from poppy_core.server.background import start_http_server

        return start_http_server(robot, request.host, request.port, start=start)
    if request.name == "ws":
        from poppy_core.server.background import start_ws_server

        return start_ws_server(robot, request.host, request.port, start=start)
    if request.name == "zmq":
        from poppy_core.server.zmqserver import start_zmq_server

        return start_zmq_server(robot, request.host, request.port, start=start)
    if request.name == "snap":
        from poppy_core.server.snap import create_snap_server

        snap = create_snap_server(robot, request.host, request.port)
        return snap.start() if start else snap.bound()
    raise ConfigError(f"no server called {request.name!r}", field=request.name)


def start_services(robot: Robot, requests: list[ServiceRequest], start: bool) -> None:
    """Start each requested server and attach it as ``robot.<name>`` (stopped by ``close``).

    Args:
        robot: the robot served.
        requests: the servers.
        start: serve now (pypot's ``start_background_services``); False binds only, the
            caller serves with ``robot.<name>.run()``.

    Raises:
        ListenError: a port is taken or an address unusable (servers already started are
            stopped by the caller's ``robot.close()``).
        ConfigError: a server this installation lacks.
    """
    for request in requests:
        server = _start(robot, request, start)
        robot.on_close(server.stop)
        robot.attach(request.name, server)
