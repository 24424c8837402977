"""`poppy serve --foxglove`: the Foxglove server's checks, warnings and line."""

from __future__ import annotations

from typing import TYPE_CHECKING

from poppy_cli.output import warn_line

if TYPE_CHECKING:
    from poppy_core.assembly import ServerSet

LOOPBACK = ("127.0.0.1", "localhost", "::1")


def check_foxglove(
    foxglove: bool, host: str, token: str | None, port: int, others: list[int]
) -> None:
    """Refuse ``--foxglove`` on another server's port (``others``; 0 is a free port each) or
    that would let others past the token (foxglove-sdk's server has no authentication); say
    what it shows to whom.

    Raises:
        ArgumentError: the port is taken, or a token and a host other than loopback (the
            caller makes it a usage error).
        MissingExtraError: foxglove-sdk is not installed.
    """
    if not foxglove:
        return
    from poppy_core.errors import ArgumentError
    from poppy_core.server.foxglove import check_access

    if port != 0 and port in others:
        raise ArgumentError(
            f"--foxglove-port {port} is also another server's port: choose another",
            field="--foxglove-port",
            value=port,
        )
    check_access(host, token)
    if host not in LOOPBACK:
        warn_line(
            f"serving Foxglove on {host}: it has no authentication, anyone who can reach this "
            "machine sees the robot and its camera (it takes no command)"
        )
    elif token:
        warn_line(
            "the Foxglove server cannot ask for the token: on loopback, every program and web "
            "page of this machine sees the robot and its camera (it takes no command)"
        )


def announce_foxglove(servers: ServerSet) -> None:
    """The server's line: where Foxglove connects."""
    server = servers.foxglove
    if server is not None:
        print(f"foxglove: {server.url} (Foxglove: Open connection, Foxglove WebSocket)", flush=True)
