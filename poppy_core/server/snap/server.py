"""``start_snap_server(robot)``: pypot's Snap! server on its own port (6969), in a thread.

The server answers only the Snap! routes and documents. Its Host and Origin rules are the REST
server's (``OriginPolicy``), with Snap!'s own origin, ``https://snap.berkeley.edu``, allowed by
default: Snap! runs there and calls the robot from the browser.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any
from urllib.parse import quote

from starlette.types import Scope

from poppy_core.motion.chains import robot_chains
from poppy_core.robot import Robot
from poppy_core.sensors import MarkerDetector
from poppy_core.server.origin_guard import OriginGuard
from poppy_core.server.origins import OriginPolicy
from poppy_core.server.runner import ServerThread
from poppy_core.server.service import RobotService
from poppy_core.server.snap.app import APP_PREFIX, create_snap_app
from poppy_core.server.snap.blocks import RobotFacts
from poppy_core.server.snap.site import SnapSite

logger = logging.getLogger(__name__)

DEFAULT_PORT = 6969
SNAP_ORIGINS = ("https://snap.berkeley.edu",)
"""Allowed on the Snap! port by default: the page the Snap! URL opens."""
SNAP_EDITOR = "https://snap.berkeley.edu/snap/snap.html"
READ_ONLY = ("/snap-blocks.xml", "/snap/", "/ip/", APP_PREFIX + "/")


def changes_state(scope: Scope) -> bool:
    """Every Snap! route may change the robot except the documents and the address."""
    path = str(scope.get("path", ""))
    return scope["type"] == "websocket" or not (path == "/" or path.startswith(READ_ONLY))


def robot_facts(service: RobotService) -> RobotFacts:
    """The robot's names now, for the blocks' defaults and the examples."""
    robot = service.robot
    primitives = service.primitives()
    chains: dict[str, list[float]] = {}
    for name, chain in robot_chains(robot).items():
        try:
            chains[name] = [float(v) for v in chain.position]
        except Exception:  # a chain that cannot compute its tip still gets blocks
            chains[name] = [0.0, 0.0, 0.1]
    cards: list[str] = []
    for sensor in robot.sensors:
        if isinstance(sensor, MarkerDetector):
            cards = list(sensor.card_ids)
            break
    return RobotFacts(
        motors=[m.name for m in robot.motors],
        groups=list(robot.motorgroups),
        primitives=list(primitives),
        properties={name: list(p.properties) for name, p in primitives.items()},
        chains=chains,
        cards=cards,
        moves=service.moves.names(),
    )


class SnapServer:
    """A running Snap! server: ``url``, ``blocks_url``, ``editor_url``, ``stop()``.

    Attributes:
        service: the robot service it uses (its own unless one was given).
        policy: its Host and Origin rules.
    """

    def __init__(
        self,
        thread: ServerThread,
        service: RobotService,
        policy: OriginPolicy,
        site: SnapSite,
        *,
        owns_service: bool,
        local_app: bool,
        token: str | None = None,
    ) -> None:
        self.thread = thread
        self._stopped = threading.Event()
        self.service = service
        self.policy = policy
        self.site = site
        self._owns_service = owns_service
        self._local_app = local_app
        self._query = f"?token={quote(token, safe='')}" if token else ""

    @property
    def port(self) -> int:
        """The port it listens on."""
        return self.thread.port

    @property
    def running(self) -> bool:
        """True while it serves."""
        return bool(self.thread.running)

    @property
    def url(self) -> str:
        """``http://host:port`` (the address a browser on another machine would use for 0.0.0.0)."""
        host = self.site.address(None)
        host = f"[{host}]" if ":" in host else host
        return f"http://{host}:{self.port}"

    @property
    def local_app(self) -> bool:
        """True when it serves a Snap! copy at ``/app/`` (the editor URL opens that copy)."""
        return self._local_app

    @property
    def blocks_url(self) -> str:
        """Where the Poppy blocks are served (with ``?token=`` when the server needs one)."""
        return f"{self.url}/snap-blocks.xml{self._query}"

    @property
    def editor_url(self) -> str:
        """The Snap! URL that opens the Poppy blocks (the local copy's with ``snap_dir``)."""
        editor = f"{self.url}{APP_PREFIX}/snap.html" if self._local_app else SNAP_EDITOR
        return f"{editor}#open:{self.blocks_url}"

    def bound(self, sibling_ports: Iterable[int] = ()) -> SnapServer:
        """Learn the bound port (documents carry it); pages of ``sibling_ports`` count as own."""
        self.thread.bind()
        self.site.port = self.thread.port
        self.policy.with_ports([self.thread.port, *sibling_ports])
        return self

    def start(self) -> SnapServer:
        """Serve (binding first when not yet bound)."""
        self.bound()
        self.thread.start()
        return self

    def run(self, timeout_s: float | None = None) -> None:
        """Serve and block until ``stop()`` (pypot's ``server.run()``); when it already serves in
        the background (``use_snap=True`` started it), return at once, as pypot did."""
        if self.thread.running:
            return
        self.start()
        self._stopped.wait(timeout_s)

    def stop(self) -> None:
        """Stop serving; stop the recordings and playbacks it started (when it owns its service)."""
        self._stopped.set()
        self.thread.stop()
        if self._owns_service:
            self.service.close()

    def __enter__(self) -> SnapServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def snap_policy(
    host: str,
    *,
    cors: Iterable[str] = (),
    allow_hosts: Iterable[str] = (),
    report: Callable[[str], None] | None = None,
) -> OriginPolicy:
    """The rules of a Snap! server: the REST server's, with snap.berkeley.edu allowed."""
    origins = [*SNAP_ORIGINS, *cors]
    return OriginPolicy.for_server(host, cors=origins, allow_hosts=allow_hosts, report=report)


def create_snap_server(
    robot: Robot,
    host: str = "127.0.0.1",
    port: int = DEFAULT_PORT,
    *,
    service: RobotService | None = None,
    policy: OriginPolicy | None = None,
    cors: Iterable[str] = (),
    allow_hosts: Iterable[str] = (),
    snap_dir: Path | None = None,
    token: str | None = None,
    report: Callable[[str], None] | None = None,
) -> SnapServer:
    """A Snap! server over ``robot``, not yet started (``.thread.bind()`` to learn its port).

    Args:
        robot: the robot (the caller keeps and closes it).
        host: address to listen on (loopback by default).
        port: port (0 picks a free one).
        service: the robot service of an HTTP server serving the same robot, to share its
            recordings and checks; by default the Snap! server makes its own.
        policy: Host and Origin rules; by default ``snap_policy(host, cors=..., ...)``.
        cors: more origins allowed besides snap.berkeley.edu (``"*"``: any page).
        allow_hosts: more Host names answered (see ``OriginPolicy``).
        snap_dir: a downloaded Snap! (the folder holding ``snap.html``) to serve under ``/app/``.
        token: require it on every route (``--token``); the blocks then carry it in their URLs.
        report: called with one line the first time an origin or a Host name is refused.
    """
    owns = service is None
    service = service or RobotService(robot)
    policy = policy or snap_policy(host, cors=cors, allow_hosts=allow_hosts, report=report)
    site = SnapSite(lambda: robot_facts(service), host, port)
    app = create_snap_app(service, site, snap_dir=snap_dir, token=token)
    thread = ServerThread(OriginGuard(app, policy, changes_state=changes_state), host, port)
    return SnapServer(
        thread, service, policy, site, owns_service=owns, local_app=bool(snap_dir), token=token
    )


def start_snap_server(
    robot: Robot, host: str = "127.0.0.1", port: int = DEFAULT_PORT, **options: Any
) -> SnapServer:
    """Serve pypot's Snap! routes for ``robot`` on ``host:port`` in a thread; ``.stop()`` ends it.

    Options are those of ``create_snap_server``. Raises ``ListenError`` for a busy port.
    """
    return create_snap_server(robot, host, port, **options).start()
