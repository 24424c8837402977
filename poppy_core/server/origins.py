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

``OriginPolicy`` holds the rules and is shared by every server of one ``poppy serve`` (REST,
pypot's WebSocket port, and any other server added later), so a refused origin is reported once
with the option that allows it. ``OriginGuard`` applies a policy to an ASGI app.
"""

from __future__ import annotations

import ipaddress
import logging
import re
import socket
from collections.abc import Callable, Iterable
from enum import Enum
from typing import Any
from urllib.parse import urlsplit

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from poppy_core.checks import robot_name
from poppy_core.server.refusals import refuse

logger = logging.getLogger(__name__)

ANY = "*"
LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
WILDCARD_HOSTS = frozenset({"", "0.0.0.0", "::"})
DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}
MAX_REPORTED = 64
"""Distinct refused origins/hosts reported (a page cycling names cannot flood the terminal)."""
MAX_CACHED = 256

SAFE_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})
PORT = re.compile(r"[0-9]{1,5}")

ALLOW_HEADERS = b"Origin, Accept, Content-Type, X-Requested-With, X-CSRF-Token, Authorization"
ALLOW_METHODS = b"GET, POST, PUT, PATCH, DELETE, OPTIONS"
PREFLIGHT_MAX_AGE = b"600"
NO_STORE = (b"cache-control", b"no-store")
PYPOT_OPEN_HEADERS = [
    NO_STORE,
    (b"access-control-allow-origin", b"*"),
    (b"access-control-allow-headers", ALLOW_HEADERS),
    (b"access-control-allow-methods", ALLOW_METHODS),
]
"""pypot's headers on every answer, kept for ``--cors '*'``."""
CROSS_SITE = (b"cross-site", b"same-site")


def normalize_origin(text: str) -> str:
    """An origin as browsers send it: ``HTTPS://Snap.Berkeley.edu:443/`` -> ``https://snap.berkeley.edu``.

    ``*`` (any origin) and ``null`` (file:// pages, sandboxed frames) are kept as they are.

    Raises:
        ValueError: ``text`` is not ``scheme://host[:port]`` with scheme http or https.
    """
    text = text.strip()
    if text in (ANY, "null"):
        return text
    parts = urlsplit(text)
    if (
        parts.scheme.lower() not in ("http", "https")
        or not parts.hostname
        or parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or parts.username is not None
    ):
        raise ValueError(
            f"{text!r} is not an origin: give scheme://host[:port], e.g. https://snap.berkeley.edu"
        )
    scheme = parts.scheme.lower()
    port = parts.port  # ValueError when out of range
    host = parts.hostname.lower()
    if ":" in host:
        host = f"[{host}]"
    suffix = f":{port}" if port is not None and port != DEFAULT_PORTS[scheme] else ""
    return f"{scheme}://{host}{suffix}"


def normalize_host(text: str) -> str:
    """A host name as the Host header carries it, without port: ``Poppy.local.`` -> ``poppy.local``.

    Raises:
        ValueError: ``text`` holds a scheme, a path or spaces.
    """
    name = text.strip().lower().rstrip(".")
    if name.startswith("[") and name.endswith("]"):
        name = name[1:-1]
    if name == ANY:
        return name
    if not name or "/" in name or " " in name or "@" in name:
        raise ValueError(f"{text!r} is not a host name: give a name such as poppy.local")
    return name


def split_host(value: str) -> tuple[str, int | None]:
    """``"[::1]:8080"`` -> ``("::1", 8080)``; ``"Localhost"`` -> ``("localhost", None)``."""
    value = value.strip().lower()
    port: int | None = None
    if value.startswith("[") and "]" in value:
        end = value.index("]")
        name, rest = value[1:end], value[end + 1 :]
        if PORT.fullmatch(rest[1:]) and rest.startswith(":"):
            port = int(rest[1:])
    elif value.count(":") == 1:
        name, _, text = value.partition(":")
        port = int(text) if PORT.fullmatch(text) else None
    else:
        name = value  # a bare IPv6 address or a name without port
    return name.rstrip("."), port


def is_ip(name: str) -> bool:
    """True for an IPv4 or IPv6 address literal."""
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def is_loopback(name: str) -> bool:
    """True for ``localhost``, ``*.localhost`` (loopback in every browser) and loopback IPs."""
    if name == "localhost" or name.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


def robot_names(name: str) -> set[str]:
    """The Host names of a robot named ``name``: ``poppy`` -> ``{"poppy", "poppy.local"}``.

    Raises:
        ValueError: ``name`` is not a robot name.
    """
    short = robot_name(name)
    return {short, f"{short}.local"}


def machine_names() -> set[str]:
    """This machine's name and its mDNS name (``poppy`` and ``poppy.local``)."""
    name = socket.gethostname().lower().rstrip(".")
    short = name.split(".")[0]
    return {n for n in (name, short, f"{short}.local") if n}


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


def default_changes_state(scope: Scope) -> bool:
    """True for what may change the robot: a WebSocket, any method but GET/HEAD/OPTIONS.

    An app with GET routes that change the robot passes its own rule, decided on the route a
    request reaches (the REST app: ``state_routes.changes_state_as_routed``).
    """
    return scope["type"] == "websocket" or scope["method"] not in SAFE_METHODS


class OriginGuard:
    """Apply an ``OriginPolicy`` to every HTTP request and WebSocket handshake of ``app``.

    Refuses foreign Host names (400) and origins (403) before the app sees them, answers
    ``OPTIONS`` preflights (204), and adds ``Cache-Control: no-store`` and, for allowed foreign
    origins, the CORS headers to every answer.

    Args:
        app: the wrapped app.
        policy: the rules (shared by the servers of one ``poppy serve``).
        changes_state: which requests may change the robot (cross-site ones without ``Origin``
            are refused); every WebSocket and non-GET request by default.
    """

    def __init__(
        self,
        app: ASGIApp,
        policy: OriginPolicy,
        changes_state: Callable[[Scope], bool] = default_changes_state,
    ) -> None:
        self.app = app
        self.policy = policy
        self.changes_state = changes_state

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        host = origin = fetch_site = None
        repeated = False
        for name, value in scope["headers"]:
            if name == b"host":
                repeated = repeated or host is not None
                host = value
            elif name == b"origin":
                repeated = repeated or origin is not None
                origin = value
            elif name == b"sec-fetch-site":
                fetch_site = value
        policy = self.policy
        if repeated or not policy.host_allowed(host):
            text = (host or b"").decode("latin-1")
            message = policy.refused_host(text) if not repeated else "repeated Host or Origin"
            tip = "open the robot by its address or a name the server allows"
            await refuse(scope, send, 400, message, tip)
            return
        allow: bytes | None = b"*" if policy.any_origin else None
        if origin is not None:
            server = scope.get("server")
            verdict = policy.verdict(origin, host, server[1] if server else None)
            if verdict is Verdict.FOREIGN:
                message = policy.refused_origin(origin.decode("latin-1"))
                await refuse(scope, send, 403, message, "the server's operator can allow it")
                return
            if verdict in (Verdict.ALLOWED, Verdict.SIBLING) and allow is None:
                allow = origin
        elif fetch_site in CROSS_SITE and not policy.any_origin and self.changes_state(scope):
            message = policy.refused_cross_site()
            await refuse(scope, send, 403, message, "use fetch() from an allowed origin")
            return
        if scope["type"] == "websocket":
            await self.app(scope, receive, send)
            return
        if allow is None:
            extra = [NO_STORE]
        elif allow == b"*":
            extra = PYPOT_OPEN_HEADERS
        else:
            extra = [NO_STORE, (b"access-control-allow-origin", allow), (b"vary", b"Origin")]
        if scope["method"] == "OPTIONS":
            await self._preflight(scope, send, extra, allow is not None)
            return

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), *extra]}
            await send(message)

        await self.app(scope, receive, send_with_headers)

    @staticmethod
    async def _preflight(
        scope: Scope, send: Send, extra: list[tuple[bytes, bytes]], cors: bool
    ) -> None:
        listed = (b"access-control-allow-headers", b"access-control-allow-methods")
        headers = [h for h in extra if h[0] not in listed]
        if cors:
            headers += [
                (b"access-control-allow-headers", ALLOW_HEADERS),
                (b"access-control-allow-methods", ALLOW_METHODS),
                (b"access-control-max-age", PREFLIGHT_MAX_AGE),
            ]
            if (b"access-control-request-private-network", b"true") in scope["headers"]:
                # Chrome asks before a public page reaches a loopback server (Private Network
                # Access): the origin is allowed, so is this.
                headers.append((b"access-control-allow-private-network", b"true"))
        await send({"type": "http.response.start", "status": 204, "headers": headers})
        await send({"type": "http.response.body", "body": b""})
