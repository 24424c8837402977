"""`poppy serve --foxglove`: the extra it needs, checked before the robot is built, and its line.

The rules (its port, the token it cannot ask for, what it shows to whom) are the spec's
(``poppy_core/assembly/serve_checks.py``), as for every server.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from poppy_core.assembly import ServerSet


def require_foxglove() -> None:
    """Raise ``MissingExtraError`` (a one-line error naming the extra) without foxglove-sdk."""
    from poppy_core.extras import require

    require("foxglove", extra="foxglove")


def announce_foxglove(servers: ServerSet) -> None:
    """The server's line: where Foxglove connects."""
    server = servers.foxglove
    if server is not None:
        print(f"foxglove: {server.url} (Foxglove: Open connection, Foxglove WebSocket)", flush=True)
