"""Host names and origins as the ``Host`` and ``Origin`` headers carry them: normalised, split
from their port, loopback or an IP address, and the robot's and the machine's own names."""

from __future__ import annotations

import ipaddress
import re
import socket
from urllib.parse import urlsplit

from poppy_core.checks import robot_name

ANY = "*"
LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
WILDCARD_HOSTS = frozenset({"", "0.0.0.0", "::"})
DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}
PORT = re.compile(r"[0-9]{1,5}")


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
