"""One TLS context for every httpx client of a test process.

httpx builds a context for each ``Client`` (``verify=True`` loads certifi's CA bundle: about
30 ms of CPU here), and the suite makes well over a thousand clients, every one of them for an
``http://`` server on loopback that never uses it. ``share_one_context`` makes those default
contexts one; a client given its own ``verify`` or ``cert`` still gets its own.
"""

from __future__ import annotations

import ssl
from typing import Any

import httpx._transports.default as httpx_transport


def share_one_context() -> None:
    """Patch httpx's transports (this process only) to reuse one default TLS context."""
    build = httpx_transport.create_ssl_context
    if getattr(build, "shared", False):
        return
    made: dict[bool, ssl.SSLContext] = {}

    def create_ssl_context(verify: Any = True, cert: Any = None, trust_env: bool = True) -> Any:
        if verify is not True or cert is not None:
            return build(verify=verify, cert=cert, trust_env=trust_env)
        if trust_env not in made:
            made[trust_env] = build(verify=True, cert=None, trust_env=trust_env)
        return made[trust_env]

    create_ssl_context.shared = True  # type: ignore[attr-defined]
    httpx_transport.create_ssl_context = create_ssl_context  # type: ignore[assignment]
