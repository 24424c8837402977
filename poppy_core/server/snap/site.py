"""``SnapSite``: the Snap! documents of one server, with the address the browser reached it by."""

from __future__ import annotations

import socket
from collections.abc import Callable
from typing import Any

from poppy_core.server.snap.blocks import RobotFacts
from poppy_core.server.snap.examples import document, project_names


def local_address(server: tuple[str, int] | None, host: str) -> str:
    """The IP a client reached this server at (``/ip/``), else this machine's main address.

    Finding the main address connects a UDP socket (which sends nothing) to a documentation
    address (TEST-NET-1), so no packet leaves the machine.
    """
    if server and server[0] not in ("", "0.0.0.0", "::"):
        return server[0]
    if host not in ("", "0.0.0.0", "::"):
        return host
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            sock.connect(("192.0.2.1", 9))
            return str(sock.getsockname()[0])
    except OSError:
        return "127.0.0.1"


class SnapSite:
    """The documents of one Snap! server: blocks and projects with its address filled in.

    Args:
        facts: a function giving the robot's names now (moves and primitives change).
        host: the address the server listens on.
        port: its port.
    """

    def __init__(self, facts: Callable[[], RobotFacts], host: str, port: int) -> None:
        self.facts = facts
        self.host = host
        self.port = port

    def _where(self, host_header: str | None) -> tuple[str, int]:
        """The host and port to write in a document: as the client reached the server."""
        if host_header:
            name, sep, port = host_header.rpartition(":")
            if sep and port.isdigit() and "]" not in port:
                return name.strip("[]"), int(port)
            return host_header.strip("[]"), self.port
        return local_address(None, self.host), self.port

    def address(self, server: Any) -> str:
        """``/ip/``."""
        return local_address(server, self.host)

    def blocks(self, host_header: str | None = None, lang: str = "en", token: str = "") -> bytes:
        """The Poppy blocks library."""
        name = "poppy-blocks-fr" if lang == "fr" else "poppy-blocks"
        body = self.project(name, host_header, token)
        assert body is not None
        return body

    def project(self, name: str, host_header: str | None = None, token: str = "") -> bytes | None:
        """A project by name, or None (``token``: the server's, written into the blocks' URLs)."""
        host, port = self._where(host_header)
        return document(name, self.facts(), host, port, token)

    @staticmethod
    def project_names() -> list[str]:
        """The projects served under ``/snap/``."""
        return project_names()
