"""Which browsers may talk to a server: the Host and Origin rules, and the ASGI guard applying them.

A server on 127.0.0.1 is reachable by every web page the user opens. Two rules keep those pages
out while scripts, pypot's clients and the server's own pages keep working:

- **Host**: the ``Host`` header must name this server: a loopback name, an IP address, the name
  given to ``--host`` (the machine's name and ``NAME.local`` when listening on every interface),
  the robot's name (``--name NAME``: ``NAME`` and ``NAME.local``, and the name its mDNS
  announcement won after a conflict) or a name the user allows. A DNS-rebinding page reaches
  the server under the attacker's name and is refused (400) before any route runs.
- **Origin**: a request a browser sends on behalf of a page of another origin carries ``Origin``
  (every cross-origin POST, ``fetch`` and WebSocket handshake). It is refused (403) unless the
  origin is the server's own (same host, one of its ports; a named robot's pages from
  ``NAME.local`` on any of the robot's ports, e.g. a monitor page on 2280) or one the user
  allowed (``--cors``);
  a state-changing request a browser sends without ``Origin`` (a link or an image pointing at a
  GET route that moves the robot) is refused when ``Sec-Fetch-Site`` says it is cross-site.
  Allowed foreign origins get CORS headers; ``*`` allows every origin (pypot's behaviour).

``OriginPolicy`` (here) holds the rules and is shared by every server of one ``poppy serve``
(REST, pypot's WebSocket port, and any other server added later), so a refused origin is
reported once with the option that allows it; ``origin_guard.OriginGuard`` applies a policy to
an ASGI app; ``host_names`` reads the names and origins the headers carry.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from enum import Enum
from typing import Any
from urllib.parse import urlsplit

from poppy_core.server.host_names import (
    ANY,
    DEFAULT_PORTS,
    LOOPBACK_NAMES,
    WILDCARD_HOSTS,
    is_ip,
    is_loopback,
    machine_names,
    normalize_host,
    normalize_origin,
    robot_names,
    split_host,
)

logger = logging.getLogger(__name__)

MAX_REPORTED = 64
"""Distinct refused origins/hosts reported (a page cycling names cannot flood the terminal)."""
MAX_CACHED = 256


class Verdict(Enum):
    """How an ``Origin`` header is treated."""

    OWN = "own"
    """A page of this server (same host, one of its ports): no CORS headers needed."""
    SIBLING = "sibling"
    """A page the named robot serves under its name on another port (a monitor page on 2280):
    the robot's own, answered with CORS headers (the browser sees another origin)."""
    ALLOWED = "allowed"
    """An origin the user allowed: answered with CORS headers."""
    FOREIGN = "foreign"
    """Refused."""


class OriginPolicy:
    """The Host names and browser origins a server accepts.

    Args:
        origins: foreign origins allowed (``"*"`` allows any, ``"null"`` file:// pages).
        hosts: Host names accepted besides loopback names and IP addresses (``"*"``: any).
        own_ports: ports of the sibling servers whose pages count as the server's own
            (the port a request arrives on always does).
        own_names: the robot's own names (``NAME``, ``NAME.local``): a page served under one of
            them on any port is the robot's own (the robot's monitor pages on their own ports).
        origin_hint: how to allow a refused origin, ``{origin}`` filled in.
        host_hint: how to allow a refused Host name, ``{host}`` filled in.
        report: called with one line the first time an origin or a Host name is refused
            (default: a WARNING of this module's logger).

    Raises:
        ValueError: an origin or a host name that is not one.
    """

    def __init__(
        self,
        origins: Iterable[str] = (),
        hosts: Iterable[str] = (),
        *,
        own_ports: Iterable[int] = (),
        own_names: Iterable[str] = (),
        origin_hint: str = "restart poppy serve with --cors {origin}",
        host_hint: str = "restart poppy serve with --allow-host {host}",
        report: Callable[[str], None] | None = None,
    ) -> None:
        self.origins = frozenset(normalize_origin(o) for o in origins)
        self.hosts = frozenset(normalize_host(h) for h in hosts) | LOOPBACK_NAMES
        self.own_ports = frozenset(own_ports)
        self.own_names = frozenset(normalize_host(n) for n in own_names)
        self.hosts |= self.own_names
        self.any_origin = ANY in self.origins
        self.any_host = ANY in self.hosts
        self.origin_hint = origin_hint
        self.host_hint = host_hint
        self.report = report or logger.warning
        self._reported: set[str] = set()
        self._hosts_seen: dict[bytes, bool] = {}
        self._origins_seen: dict[tuple[bytes, bytes, int | None], Verdict] = {}

    @classmethod
    def for_server(
        cls,
        host: str,
        *,
        cors: Iterable[str] = (),
        allow_hosts: Iterable[str] = (),
        name: str | None = None,
        **options: Any,
    ) -> OriginPolicy:
        """The policy of a server listening on ``host`` (``--host``, ``--cors``, ``--allow-host``,
        ``--name``).

        The name given to ``--host`` is accepted; listening on every interface (``0.0.0.0``,
        ``::``) also accepts this machine's name and ``NAME.local``. A robot ``name`` is accepted
        as ``NAME`` and ``NAME.local``, and its pages on any port count as its own.
        """
        if name is not None:
            options["own_names"] = robot_names(name)
        names = set(allow_hosts)
        bare = host.strip("[]").lower()
        if bare in WILDCARD_HOSTS:
            names |= machine_names()
        elif not is_ip(bare):
            names.add(bare)
        return cls(cors, names, **options)

    def with_ports(self, ports: Iterable[int]) -> OriginPolicy:
        """Count pages served on ``ports`` (sibling servers) as the server's own; returns self."""
        self.own_ports = self.own_ports | frozenset(ports)
        self._origins_seen.clear()
        return self

    def with_names(self, names: Iterable[str]) -> OriginPolicy:
        """Accept ``names`` as the robot's own too (the mDNS name won after a conflict, a new
        name set from the settings); returns self."""
        own: set[str] = set()
        for name in names:
            own |= robot_names(name)
        self.own_names = self.own_names | own
        self.hosts = self.hosts | own
        self._hosts_seen.clear()
        self._origins_seen.clear()
        return self

    # -- decisions -----------------------------------------------------------------------------

    def host_allowed(self, host: bytes | None) -> bool:
        """True when a ``Host`` header (bytes, port included) names this server."""
        if host is None or self.any_host:
            return True  # HTTP/1.0 clients send none; browsers always do
        known = self._hosts_seen.get(host)
        if known is None:
            name, _ = split_host(host.decode("latin-1"))
            known = name in self.hosts or is_loopback(name) or is_ip(name)
            if len(self._hosts_seen) >= MAX_CACHED:
                self._hosts_seen.clear()
            self._hosts_seen[host] = known
        return known

    def verdict(self, origin: bytes, host: bytes | None, port: int | None) -> Verdict:
        """How the ``Origin`` of a request reaching ``host`` on ``port`` is treated."""
        key = (origin, host or b"", port)
        found = self._origins_seen.get(key)
        if found is None:
            found = self._verdict(origin.decode("latin-1"), host, port)
            if len(self._origins_seen) >= MAX_CACHED:
                self._origins_seen.clear()
            self._origins_seen[key] = found
        return found

    def _verdict(self, origin: str, host: bytes | None, port: int | None) -> Verdict:
        try:
            normal = normalize_origin(origin)
        except ValueError:
            return Verdict.ALLOWED if self.any_origin else Verdict.FOREIGN
        if normal not in (ANY, "null") and host is not None:
            own = self._own(normal, host, port)
            if own is not None:
                return own
        if self.any_origin or normal in self.origins:
            return Verdict.ALLOWED
        return Verdict.FOREIGN

    def _own(self, origin: str, host: bytes, port: int | None) -> Verdict | None:
        parts = urlsplit(origin)
        name = (parts.hostname or "").lower()
        origin_port = parts.port or DEFAULT_PORTS.get(parts.scheme)
        host_name, host_port = split_host(host.decode("latin-1"))
        if name == host_name and origin_port == (host_port or DEFAULT_PORTS.get(parts.scheme)):
            return Verdict.OWN  # same origin: a page served under the name it was reached by
        ports = self.own_ports | ({port} if port is not None else set())
        if origin_port in ports and (
            name == host_name or is_loopback(name) or (name in self.hosts and not is_ip(name))
        ):
            return Verdict.OWN
        if name in self.own_names:
            return Verdict.SIBLING  # a page the named robot serves on another of its ports
        return None

    # -- reports -------------------------------------------------------------------------------

    def refused_origin(self, origin: str) -> str:
        """The one-line message for a refused origin (reported once per origin)."""
        text = origin[:200]
        try:
            hint = self.origin_hint.format(origin=_quoted(normalize_origin(text)))
        except ValueError:
            hint = "it is not a valid origin"
        message = f"refused a request from the web page origin {text!r}: to allow it, {hint}"
        self._report(f"origin {text}", message)
        return message

    def refused_cross_site(self) -> str:
        """The message for a cross-site request without ``Origin`` that would change the robot."""
        hint = self.origin_hint.format(origin="ORIGIN")
        message = (
            "refused a request that a page of another site made the browser send (a link or an "
            "image pointing at a route that changes the robot): to let a page do that, make it "
            f"use fetch() and {hint}"
        )
        self._report("cross-site", message)
        return message

    def refused_host(self, host: str) -> str:
        """The one-line message for a refused Host name (reported once per name)."""
        name, _ = split_host(host[:200])
        message = (
            f"refused a request for host {name!r}, a name this server was not started for "
            f"(a DNS-rebinding page uses such names): if you reach the robot by that name, "
            f"{self.host_hint.format(host=_quoted(name))}"
        )
        self._report(f"host {name}", message)
        return message

    def _report(self, key: str, message: str) -> None:
        if key in self._reported or len(self._reported) >= MAX_REPORTED:
            logger.debug("%s", message)
            return
        self._reported.add(key)
        self.report(message)


def _quoted(value: str) -> str:
    """``value`` for a suggested command line: as Python quotes it, without the quotes, so a
    control character a client sent (``\x9b``) is shown escaped, never written raw."""
    return repr(value)[1:-1]
