"""``Announcer``: a served robot's name on the network over mDNS/DNS-SD (python-zeroconf).

``poppy serve --name NAME --announce`` registers an address record for ``NAME.local``, an
``_http._tcp`` service (the page, for any DNS-SD browser) and a ``_poppy._tcp`` service whose
TXT records say what the robot is (``creature``, ``name``, ``version``, one key per served
port: ``http=8080``, ``ws=9009``, ``snap=6969``, ``zmq=6768``; ``token=1`` when one is required,
never the token). Announcing happens only when asked, on the interfaces the servers listen on
(a server on 127.0.0.1 is announced on loopback only). A name someone else answers for gets the
usual suffix (``poppy`` taken: ``poppy-2``, then ``poppy-3``...); ``name`` is the one won, which
the Host check must accept (``serve`` adds it to the policy).
"""

from __future__ import annotations

import ipaddress
import logging
import socket
import threading
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from poppy_core.extras import require
from poppy_core.server.errors import ListenError

if TYPE_CHECKING:
    from zeroconf import ServiceInfo, Zeroconf

logger = logging.getLogger(__name__)

POPPY_TYPE = "_poppy._tcp.local."
"""The DNS-SD type of a poppy robot (``poppy_core.remote.discovery`` browses it)."""
HTTP_TYPE = "_http._tcp.local."
MAX_SUFFIX = 20
"""``NAME-2`` ... ``NAME-20`` are tried when ``NAME`` is taken."""
PROBE_MS = 2000
"""How long an address query for a candidate name waits for an answer: past the one second
during which a responder does not multicast the same record again (RFC 6762, section 6), so
the query's second try is answered even right after another one."""
WILDCARD = frozenset({"", "0.0.0.0", "::"})


def candidates(name: str) -> list[str]:
    """The names tried in order: ``poppy``, ``poppy-2``, ``poppy-3``..."""
    return [name] + [f"{name}-{n}" for n in range(2, MAX_SUFFIX + 1)]


def announced_addresses(listen_host: str) -> list[str]:
    """The IPv4 addresses announced for a server listening on ``listen_host``: that address,
    or every non-loopback one of this machine when listening on every interface."""
    host = listen_host.strip("[]")
    if host not in WILDCARD:
        return [host] if _is_ipv4(host) else ["127.0.0.1"]
    import ifaddr  # zeroconf's own dependency

    found = [
        str(ip.ip)
        for adapter in ifaddr.get_adapters()
        for ip in adapter.ips
        if isinstance(ip.ip, str) and not ipaddress.ip_address(ip.ip).is_loopback
    ]
    return found or ["127.0.0.1"]


def _is_ipv4(text: str) -> bool:
    try:
        return ipaddress.ip_address(text).version == 4
    except ValueError:
        return False


class Announcer:
    """Announce one robot's name and services until ``stop()``.

    Args:
        name: the name asked for (a DNS label: ``poppy``).
        ports: protocol -> port served (``http``, ``ws``, ``snap``, ``zmq``).
        listen_host: the address the servers listen on (what is announced, and where).
        properties: more TXT records (``creature``, ``version``, ``token``).
        on_name: called with the name won, at start and after each rename.

    Raises:
        MissingExtraError: zeroconf is not installed (the ``appliance`` extra).
    """

    def __init__(
        self,
        name: str,
        ports: Mapping[str, int],
        *,
        listen_host: str = "127.0.0.1",
        properties: Mapping[str, str] | None = None,
        on_name: Callable[[str], None] | None = None,
    ) -> None:
        require("zeroconf", extra="appliance")
        self.asked = name
        self.name = name
        self.ports = dict(ports)
        self.listen_host = listen_host
        self.properties = dict(properties or {})
        self.on_name = on_name
        self.addresses = announced_addresses(listen_host)
        self._zc: Zeroconf | None = None
        self._infos: list[ServiceInfo] = []
        self._lock = threading.Lock()

    @property
    def host(self) -> str:
        """The announced host name, ``poppy.local``."""
        return f"{self.name}.local"

    def start(self) -> str:
        """Take a free name, register the records; returns the name won.

        Raises:
            ListenError: mDNS cannot be used on that interface.
        """
        from zeroconf import InterfaceChoice, IPVersion, Zeroconf

        host = self.listen_host.strip("[]")
        interfaces: Any = InterfaceChoice.All if host in WILDCARD else self.addresses
        with self._lock:
            try:
                self._zc = Zeroconf(interfaces=interfaces, ip_version=IPVersion.V4Only)
            except OSError as exc:
                raise ListenError(
                    f"cannot announce {self.asked}.local over mDNS on {host or 'every interface'}"
                    f": {exc.strerror or exc}"
                ) from None
            self._register(self.asked)
        return self.name

    def rename(self, name: str) -> str:
        """Announce under ``name`` instead (the settings' new name); returns the name won."""
        with self._lock:
            if self._zc is None:
                self.asked = self.name = name
                return name
            self._unregister()
            self.asked = name
            self._register(name)
        return self.name

    def stop(self) -> None:
        """Withdraw the records (goodbye packets) and close the sockets; again: nothing."""
        with self._lock:
            if self._zc is None:
                return
            try:
                self._unregister()
            finally:
                self._zc.close()
                self._zc = None

    def _register(self, asked: str) -> None:
        assert self._zc is not None
        self.name = self._free_name(asked)
        self._infos = self._service_infos(self.name)
        for info in self._infos:
            self._zc.register_service(info, allow_name_change=True)
        logger.info("announced %s.local (%s)", self.name, ", ".join(self.addresses))
        if self.name != asked:
            logger.warning(
                "the name %s.local is taken on this network: this robot is %s.local",
                asked,
                self.name,
            )
        if self.on_name is not None:
            self.on_name(self.name)

    def _unregister(self) -> None:
        assert self._zc is not None
        for info in self._infos:
            self._zc.unregister_service(info)
        self._infos = []

    def _free_name(self, asked: str) -> str:
        """The first candidate whose ``NAME.local`` nobody answers for (a robot announcing
        ``_poppy._tcp`` under a name answers its address too)."""
        from zeroconf._services.info import AddressResolver  # not re-exported as typed

        assert self._zc is not None
        for name in candidates(asked):
            if not AddressResolver(f"{name}.local.").request(self._zc, PROBE_MS):
                return name
        return asked  # every suffix taken: zeroconf renames the services themselves

    def _service_infos(self, name: str) -> list[ServiceInfo]:
        from zeroconf import ServiceInfo

        server = f"{name}.local."
        addresses = [socket.inet_aton(a) for a in self.addresses]
        txt = {**self.properties, "name": name, **{k: str(v) for k, v in self.ports.items()}}
        main = self.ports.get("http") or next(iter(self.ports.values()), 0)
        infos = [
            ServiceInfo(
                POPPY_TYPE,
                f"{name}.{POPPY_TYPE}",
                port=main,
                properties=txt,
                server=server,
                addresses=addresses,
            )
        ]
        if "http" in self.ports:
            infos.append(
                ServiceInfo(
                    HTTP_TYPE,
                    f"{name}.{HTTP_TYPE}",
                    port=self.ports["http"],
                    properties={"path": "/"},
                    server=server,
                    addresses=addresses,
                )
            )
        return infos
