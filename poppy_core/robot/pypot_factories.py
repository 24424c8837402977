"""pypot's ``from_remote(host, port)``: the client of a served robot.

pypot's ``from_json`` builds a robot, so it is the assembly's (``poppy_core.assembly.build``);
user code imports both from ``poppy_core.pypot``.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from poppy_core.remote import RemoteRobot
    from poppy_core.zenoh_wire import ZenohSettings


ROBOT_URL_VARIABLE = "POPPY_ROBOT_URL"
"""The robot a notebook reaches by default (``poppy notebook --robot URL`` sets it)."""
TOKEN_VARIABLE = "POPPY_TOKEN"
DEFAULT_ROBOT_URL = "http://127.0.0.1:8080"


def from_remote(
    host: str | None = None,
    port: int = 8080,
    *,
    token: str | None = None,
    zenoh: ZenohSettings | None = None,
) -> RemoteRobot:
    """The robot served by ``poppy serve --http`` on ``host:port`` (pypot's ``from_remote``), or
    by ``poppy serve --zenoh --name NAME`` for ``host="zenoh:NAME"`` (``zenoh``: the endpoints
    to connect to; by default POPPY_ZENOH_CONNECT, else ``tcp/127.0.0.1:7447``).

    Without ``host``: the robot of ``$POPPY_ROBOT_URL`` (which ``poppy notebook`` gives its
    notebooks), else ``http://127.0.0.1:8080``; the token then defaults to ``$POPPY_TOKEN``.

    Returns:
        A ``poppy_core.remote.RemoteRobot`` (motors, groups and primitives as attributes, over
        HTTP).

    Raises:
        CommunicationError: nothing answers there, or it is not a poppy server.
    """
    from poppy_core.remote import RemoteRobot

    if host is None:
        url = os.environ.get(ROBOT_URL_VARIABLE) or DEFAULT_ROBOT_URL
        token = token if token is not None else (os.environ.get(TOKEN_VARIABLE) or None)
    elif host.startswith("zenoh:"):
        return RemoteRobot(host, token=token, zenoh=zenoh)
    else:
        url = host if "://" in host else f"http://{_bracketed(host)}:{int(port)}"
    return RemoteRobot(url, token=token)


def _bracketed(host: str) -> str:
    return f"[{host}]" if ":" in host and not host.startswith("[") else host
