"""Virtual Ergo Jrs served on Zenoh on loopback (explicit endpoints, scouting off), for tests."""

from __future__ import annotations

import socket

from poppy_core import from_profile
from poppy_core.assembly import ServerSet, ServeSpec, ZenohSettings, serve
from poppy_core.remote.zenoh_fleet import DEFAULT_TIMEOUT_S
from poppy_core.robot import Robot
from tests.helpers.waiting import scaled

TOKEN = "s3cret"


def fleet_timeout_s() -> float:
    """How long a test's fleet client waits for answers: the product's timeout times the load
    factor measured now (a loaded machine answered after the fixed 2 s)."""
    return scaled(DEFAULT_TIMEOUT_S)


def free_endpoint() -> str:
    """A Zenoh endpoint on a free loopback port."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{sock.getsockname()[1]}"


class Served:
    """A virtual Ergo Jr served on Zenoh as ``poppy/NAME``, listening on ``endpoint``, or
    connected only to the router at ``router`` (then ``endpoint`` is the router's)."""

    def __init__(self, name: str, token: str | None = TOKEN, router: str | None = None) -> None:
        self.name = name
        self.endpoint = router or free_endpoint()
        self.robot: Robot = from_profile("ergo-jr", sim=True)
        settings = (
            ZenohSettings(connect=(router,)) if router else ZenohSettings(listen=(self.endpoint,))
        )
        spec = ServeSpec(zenoh=settings, name=name, token=token)
        self.servers: ServerSet = serve(self.robot, spec)

    def close(self) -> None:
        self.servers.stop()
        self.robot.close()


def connect_to(*served: Served) -> tuple[str, ...]:
    """The endpoints a client connects to, to reach ``served``."""
    return tuple(s.endpoint for s in served)
