"""``discover()``: the robots announced on the network (``poppy serve --announce``), over mDNS.

Browses the ``_poppy._tcp`` DNS-SD services for ``timeout_s`` and reads each one's TXT records
(creature, name, version, a port per protocol) and address. ``resolve()`` finds the addresses
of one ``NAME.local``. Both listen on every interface unless given ``interfaces`` (the tests
stay on loopback: ``["127.0.0.1"]``). Needs zeroconf (the ``appliance`` extra).
"""

from __future__ import annotations

import ipaddress
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from poppy_core import checks
from poppy_core.errors import ArgumentError
from poppy_core.extras import require

POPPY_TYPE = "_poppy._tcp.local."
"""The type the server's announcer registers (``poppy_core.server.announce``: the server room
is above this one, so the constant is written in both)."""
PROTOCOLS = ("http", "ws", "snap", "zmq")
SCHEMES = {"http": "http://{h}:{p}/", "ws": "ws://{h}:{p}/", "snap": "http://{h}:{p}/"}
SCHEMES["zmq"] = "tcp://{h}:{p}"
RESOLVE_MS = 2000
MIN_TIMEOUT_S = 0.1
MAX_TIMEOUT_S = 120.0
"""How long the details of one announced robot are waited for."""


@dataclass(frozen=True)
class AnnouncedRobot:
    """One robot found on the network."""

    name: str
    host: str
    """``poppy.local``."""
    creature: str
    version: str
    addresses: tuple[str, ...]
    ports: dict[str, int] = field(default_factory=dict)
    token: bool = False
    """True when its server asks for a token."""

    @property
    def urls(self) -> dict[str, str]:
        """Protocol -> URL by name (``http://poppy.local:8080/``)."""
        return {p: SCHEMES[p].format(h=self.host, p=port) for p, port in self.ports.items()}

    def as_dict(self) -> dict[str, Any]:
        """The ``--json`` shape of ``poppy fleet discover``."""
        return {
            "name": self.name,
            "host": self.host,
            "creature": self.creature,
            "version": self.version,
            "addresses": list(self.addresses),
            "ports": dict(self.ports),
            "urls": self.urls,
            "token": self.token,
        }


def _interfaces(interfaces: Sequence[str] | None) -> Any:
    """zeroconf's interfaces: these IPv4 addresses, or every interface.

    Raises:
        ArgumentError: an interface that is not an IPv4 address.
    """
    from zeroconf import InterfaceChoice

    if not interfaces:
        return InterfaceChoice.All
    for address in interfaces:
        try:
            ipaddress.IPv4Address(address)
        except ValueError:
            raise ArgumentError(
                f"interface {address!r} is not an IPv4 address: give this machine's address "
                "on that network, e.g. 192.168.1.20 (127.0.0.1: this machine only)",
                field="interface",
                value=address,
            ) from None
    return list(interfaces)


def _zeroconf(interfaces: Sequence[str] | None) -> Any:
    """A zeroconf instance listening on ``interfaces`` (every one by default).

    Raises:
        ArgumentError: an interface that is not an IPv4 address of this machine.
    """
    from zeroconf import IPVersion, Zeroconf

    chosen = _interfaces(interfaces)
    try:
        return Zeroconf(interfaces=chosen, ip_version=IPVersion.V4Only)
    except OSError as exc:
        raise ArgumentError(
            f"cannot listen for mDNS on {', '.join(interfaces or ['every interface'])}: "
            f"{exc.strerror or exc} (give an address of this machine)",
            field="interface",
        ) from None


def discover(
    timeout_s: float = 3.0, interfaces: Sequence[str] | None = None
) -> list[AnnouncedRobot]:
    """The robots announced within ``timeout_s`` seconds, sorted by name.

    Raises:
        ArgumentError: ``timeout_s`` is not 0.1 to 120 s, an interface not an IPv4 address.
        MissingExtraError: zeroconf is not installed (the ``appliance`` extra).
    """
    timeout_s = checks.in_range(timeout_s, MIN_TIMEOUT_S, MAX_TIMEOUT_S, "timeout", "s")
    require("zeroconf", extra="appliance", feature="discovering robots")
    from zeroconf import ServiceBrowser, ServiceStateChange, Zeroconf

    names: set[str] = set()
    lock = threading.Lock()

    def changed(
        zeroconf: Zeroconf, service_type: str, name: str, state_change: ServiceStateChange
    ) -> None:
        if state_change is not ServiceStateChange.Removed:
            with lock:
                names.add(name)

    zc = _zeroconf(interfaces)
    try:
        browser = ServiceBrowser(zc, POPPY_TYPE, handlers=[changed])
        time.sleep(timeout_s)
        browser.cancel()
        with lock:
            found = sorted(names)
        robots = [r for r in (_details(zc, name) for name in found) if r is not None]
    finally:
        zc.close()
    return sorted(robots, key=lambda r: r.name)


def _details(zc: Any, name: str) -> AnnouncedRobot | None:
    info = zc.get_service_info(POPPY_TYPE, name, RESOLVE_MS)
    if info is None:
        return None
    txt = {
        k.decode("utf-8", "replace"): (v or b"").decode("utf-8", "replace")
        for k, v in info.properties.items()
    }
    ports = {p: int(txt[p]) for p in PROTOCOLS if txt.get(p, "").isdigit()}
    short = txt.get("name") or name.removesuffix(f".{POPPY_TYPE}")
    server = (info.server or f"{short}.local.").rstrip(".")
    return AnnouncedRobot(
        name=short,
        host=server,
        creature=txt.get("creature", ""),
        version=txt.get("version", ""),
        addresses=tuple(info.parsed_addresses()),
        ports=ports,
        token=txt.get("token") == "1",
    )


def resolve(
    host: str, timeout_s: float = 3.0, interfaces: Sequence[str] | None = None
) -> list[str]:
    """The addresses ``host`` (``poppy.local``) answers with over mDNS; empty when none did.

    Raises:
        ArgumentError: ``timeout_s`` is not 0.1 to 120 s, an interface not an IPv4 address.
        MissingExtraError: zeroconf is not installed (the ``appliance`` extra).
    """
    timeout_s = checks.in_range(timeout_s, MIN_TIMEOUT_S, MAX_TIMEOUT_S, "timeout", "s")
    require("zeroconf", extra="appliance", feature="resolving .local names")
    from zeroconf._services.info import AddressResolver  # not re-exported as typed

    zc = _zeroconf(interfaces)
    try:
        resolver = AddressResolver(host.rstrip(".") + ".")
        if not resolver.request(zc, int(timeout_s * 1000)):
            return []
        return list(resolver.parsed_addresses())
    finally:
        zc.close()
