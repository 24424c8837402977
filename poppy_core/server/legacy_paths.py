"""The REST route spellings of pypot's first HTTP server, which the Poppy documentation shows
(``/motor/list.json``, ``/motor/m3/register/present_position``, ``/primitive/dance/start.json``):
each is rewritten to today's route (``/motors/...``, ``/primitives/...``) before routing, so
both answer the same.
"""

from __future__ import annotations

import re
from typing import Any

NAME = r"[A-Za-z0-9_]+"
REWRITES: tuple[tuple[re.Pattern[str], str], ...] = tuple(
    (re.compile(f"^{pattern}$"), replacement)
    for pattern, replacement in (
        (r"/motor/list\.json", "/motors/list.json"),
        (r"/motor/alias/list\.json", "/motors/aliases/list.json"),
        (r"/motor/goto\.json", "/motors/goto.json"),
        (rf"/motor/({NAME})/list\.json", r"/motors/\1/list.json"),
        (rf"/motor/({NAME})/register/list\.json", r"/motors/\1/registers/list.json"),
        (
            rf"/motor/({NAME})/register/({NAME})(?:/value\.json)?",
            r"/motors/\1/registers/\2/value.json",
        ),
        (rf"/motor/({NAME})/goto\.json", r"/motors/\1/goto.json"),
        (r"/primitive/list\.json", "/primitives/list.json"),
        (r"/primitive/running/list\.json", "/primitives/running/list.json"),
        (rf"/primitive/({NAME})/(start|stop|pause|resume)\.json", r"/primitives/\1/\2.json"),
        (rf"/primitive/({NAME})/property/list\.json", r"/primitives/\1/properties/list.json"),
        (
            rf"/primitive/({NAME})/property/({NAME})(?:/value\.json)?",
            r"/primitives/\1/properties/\2/value.json",
        ),
        (rf"/primitive/({NAME})/method/list\.json", r"/primitives/\1/methods/list.json"),
        (
            rf"/primitive/({NAME})/method/({NAME})/args\.json",
            r"/primitives/\1/methods/\2/args.json",
        ),
    )
)


def current_path(path: str) -> str | None:
    """Today's route for an old spelling, None for any other path."""
    if not path.startswith(("/motor/", "/primitive/")):
        return None
    for pattern, replacement in REWRITES:
        if pattern.match(path):
            return pattern.sub(replacement, path)
    return None


class LegacyPaths:
    """ASGI middleware: requests to an old spelling are routed as the current one."""

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] == "http":
            path = current_path(scope["path"])
            if path is not None:
                scope = {**scope, "path": path, "raw_path": path.encode()}
        await self.app(scope, receive, send)
