"""The servers a creature class starts (``use_http``, ``use_ws``, ``use_zmq``, ``use_snap``).

The one module of ``creatures`` that reaches the server room, and only inside functions: pypot's
creature constructors start servers, so ``PoppyErgoJr(use_http=True)`` must too. Each server is
attached to the robot under pypot's name (``robot.http``, ``robot.snap``...) and stopped by
``robot.close()``.
"""

from __future__ import annotations

import importlib.util
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
        return _optional("snap", "start_snap_server", "use_snap")(
            robot, request.host, request.port
        )
    raise ConfigError(f"no server called {request.name!r}", field=request.name)


def _optional(module: str, function: str, option: str) -> Any:
    """``poppy_core.server.<module>.<function>``, or a one-line error when it is not there."""
    name = f"poppy_core.server.{module}"
    if importlib.util.find_spec(name) is None:
        raise ConfigError(
            f"{option}=True needs the {module} server ({name}), which this poppy does not have; "
            f"leave {option} out",
            field=option,
        )
    return getattr(importlib.import_module(name), function)


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
