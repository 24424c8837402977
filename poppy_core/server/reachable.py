"""Where a served robot is reachable: a Zenoh endpoint or a page URL on every interface
(``0.0.0.0``, ``::``) named by this machine's own addresses, as a peer must dial them."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from urllib.parse import urlsplit, urlunsplit

from poppy_core.server.announce import WILDCARD, announced_addresses


def machine_addresses() -> list[str]:
    """This machine's non-loopback IPv4 addresses (``127.0.0.1`` when it has none; none
    without ifaddr, the ``fleet`` extra's: the wildcard is left as it is)."""
    try:
        return announced_addresses("0.0.0.0")
    except ImportError:
        return []


def _bracketed(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def reachable_endpoints(
    endpoints: Iterable[str], addresses: Sequence[str] | None = None
) -> list[str]:
    """``endpoints`` (``tcp/0.0.0.0:7447``, ``tcp/[::]:7447#iface=wlan0``) with each one on every
    interface replaced by one per address of this machine (``addresses``: those instead);
    the others as they are."""
    out: list[str] = []
    for endpoint in endpoints:
        where, hash_, meta = endpoint.partition("#")
        protocol, slash, address = where.partition("/")
        host, colon, port = address.rpartition(":")
        if not (slash and colon) or host.strip("[]") not in WILDCARD:
            out.append(endpoint)
            continue
        found = machine_addresses() if addresses is None else addresses
        out += [f"{protocol}/{_bracketed(ip)}:{port}{hash_}{meta}" for ip in found] or [endpoint]
    return list(dict.fromkeys(out))


def reachable_url(url: str | None, addresses: Sequence[str] | None = None) -> str | None:
    """``url`` with a host on every interface (``http://0.0.0.0:8080``) replaced by this
    machine's first address (``addresses``: the first of those); others as they are."""
    if url is None:
        return None
    parts = urlsplit(url)
    if (parts.hostname or "") not in WILDCARD or not parts.netloc:
        return url
    found = machine_addresses() if addresses is None else list(addresses)
    if not found:
        return url
    netloc = _bracketed(found[0]) + (f":{parts.port}" if parts.port is not None else "")
    return urlunsplit(parts._replace(netloc=netloc))
