"""``ServeSpec``: what to serve a robot with (which servers, where, the token, the origins, the
name), and ``Listen``, one server's address. A spec checks itself when it is made
(``serve_checks``): the CLI's ``poppy serve`` and Python's ``serve()`` get the same refusals.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from poppy_core.assembly.serve_checks import (
    check_foxglove,
    check_origins,
    check_ports,
    exposure,
)
from poppy_core.checks import robot_name
from poppy_core.ros2_wire import Ros2Settings
from poppy_core.zenoh_wire import ZenohSettings

if TYPE_CHECKING:
    from poppy_core.server import OriginPolicy

logger = logging.getLogger(__name__)

DEFAULT_PORTS = {"http": 8080, "ws": 9009, "zmq": 6768, "snap": 6969}
"""pypot's default ports (``zmq``: the documentation's ZMQ example)."""
LOOPBACK = "127.0.0.1"

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Listen:
    """Where one server listens (``port`` 0 picks a free one)."""

    host: str = LOOPBACK
    port: int = 0


@dataclass(frozen=True)
class ServeSpec:
    """Which servers to build for a robot, and the rules they share.

    Attributes:
        http: the REST API and page (with the stream at ``/api/v1/ws``), or None.
        ws: pypot's WebSocket port (the state stream at ``/``), or None.
        zmq: pypot's ZMQ request/reply server, or None.
        snap: the Snap! server, or None.
        token: required on every route and WebSocket (not ZMQ, which has none).
        cors: browser origins allowed besides the servers' own pages (``"*"``: any).
        allow_hosts: Host names answered besides loopback names, IPs and the listening host.
        ws_rate_hz: the state stream's default rate.
        snap_dir: a downloaded Snap! served at ``/app/`` on the Snap! port.
        name: the robot's name (``checks.robot_name``: one DNS label, kept lower case; a bad
            one is an ArgumentError here): ``NAME`` and ``NAME.local`` are accepted as Host
            names, and the pages the robot serves under them on any port count as its own; on
            Zenoh the robot is ``poppy/NAME`` (the host's name when None).
        announce: announce ``NAME.local`` (default ``poppy``) and the robot's services over
            mDNS/DNS-SD on the interfaces the servers listen on (``appliance`` extra).
        http_alias_ports: more ports serving the REST API and page, on ``http``'s host (the
            appliance serves port 80 and keeps 8080); their pages count as the server's own.
        report: called with one line the first time an origin or Host name is refused.
        zenoh: the robot on Zenoh under ``poppy/<name>`` (``ZenohSettings``: endpoints,
            configuration file, scouting), or None.
        state_rate_hz: the Zenoh state messages per second (the sync loop's rate).
        ros2: the robot as a ROS 2 node on rmw_zenoh's wire (``Ros2Settings``: domain,
            namespace, node; its Zenoh settings serve when ``zenoh`` is None), or None.
        foxglove: foxglove-sdk's WebSocket server for the Foxglove app (read only; it has no
            authentication: with a token it serves on loopback only), or None.
        settings_file: the appliance's serve options file (``poppy serve --settings``): the
            page's settings switch Snap! and ZMQ there.
        token_file: the file ``token`` was read from (``--token-file``): the page's settings
            change the token there.
        warn: called with each exposure warning when the spec is made (a server on another
            address than loopback without a token, ZMQ off loopback, ``cors`` ``"*"``);
            default: a WARNING of this module's logger.

    A spec checks itself when it is made (``serve_checks``): a port that clashes, a name, an
    origin or a Host name that is not one is an ``ArgumentError`` (a ``ValueError``) whose
    ``field`` names the attribute; then the exposure warnings are given to ``warn``.
    """

    http: Listen | None = None
    ws: Listen | None = None
    zmq: Listen | None = None
    snap: Listen | None = None
    token: str | None = None
    cors: tuple[str, ...] = ()
    allow_hosts: tuple[str, ...] = ()
    ws_rate_hz: float = 30.0
    snap_dir: Path | None = None
    name: str | None = None
    announce: bool = False
    http_alias_ports: tuple[int, ...] = ()
    report: Callable[[str], None] | None = field(default=None, compare=False)
    zenoh: ZenohSettings | None = None
    state_rate_hz: float = 50.0
    ros2: Ros2Settings | None = None
    foxglove: Listen | None = None
    settings_file: Path | None = None
    token_file: Path | None = None
    warn: Callable[[str], None] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        """Check the spec: ``name`` as the robot's one name on mDNS and Zenoh
        (``checks.robot_name``: ``Poppy.local`` -> ``poppy``), the ports, the origins and Host
        names (ArgumentError, a ValueError); then warn of what it exposes."""
        if self.name is not None:
            object.__setattr__(self, "name", robot_name(self.name, "name"))
        check_ports(self)
        check_foxglove(self)
        check_origins(self)
        for line in exposure(self):
            (self.warn or logger.warning)(line)

    def policy(self) -> OriginPolicy:
        """The Host and Origin rules of the HTTP and WebSocket servers, made from the spec (a
        new one each call: a server set adds its own ports and names to it)."""
        from poppy_core.server import OriginPolicy

        return OriginPolicy.for_server(
            self.host,
            cors=self.cors,
            allow_hosts=self.allow_hosts,
            name=self.name,
            report=self.report,
        )

    def snap_policy(self, host: str) -> OriginPolicy:
        """The Snap! server's rules on ``host``: the REST server's, snap.berkeley.edu allowed,
        the robot's name its own."""
        from poppy_core.server.snap.server import snap_policy

        policy = snap_policy(host, cors=self.cors, allow_hosts=self.allow_hosts, report=self.report)
        if self.name is not None:
            policy.with_names([self.name])  # Snap! projects call http://poppy.local:6969 too
        return policy

    def listens(self) -> dict[str, Listen]:
        """Protocol -> where it listens, for the servers asked for, in starting order."""
        wanted = {
            "http": self.http,
            "ws": self.ws,
            "zmq": self.zmq,
            "snap": self.snap,
            "foxglove": self.foxglove,
        }
        return {name: where for name, where in wanted.items() if where is not None}

    @property
    def host(self) -> str:
        """The address the policy is made for: the first server's (loopback when none)."""
        listens = list(self.listens().values())
        return listens[0].host if listens else LOOPBACK
