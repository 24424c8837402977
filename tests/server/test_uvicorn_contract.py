"""What server/limits.py relies on in uvicorn, beyond its documented API, still holds.

pyproject bounds uvicorn to the minor versions tested; when the bound is raised, these say at
once whether the new version still has what the protocol subclasses use.
"""

from __future__ import annotations

import asyncio
import inspect
import tomllib
from importlib.metadata import version
from pathlib import Path

from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[2]


def _declared(name: str) -> Requirement:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    found = [Requirement(r) for reqs in extras.values() for r in reqs]
    return next(r for r in found if r.name == name)


def test_uvicorn_has_an_upper_bound_that_the_installed_version_meets() -> None:
    declared = _declared("uvicorn")
    assert any(spec.operator == "<" for spec in declared.specifier), declared
    assert declared.specifier.contains(version("uvicorn")), (declared, version("uvicorn"))


def test_the_http_protocol_has_the_attributes_the_guard_uses() -> None:
    import uvicorn
    from uvicorn.protocols.http.auto import AutoHTTPProtocol
    from uvicorn.server import ServerState

    async def app(scope: object, receive: object, send: object) -> None:
        return None

    config = uvicorn.Config(app, log_level="error")
    config.load()
    loop = asyncio.new_event_loop()
    try:
        protocol = AutoHTTPProtocol(
            config=config, server_state=ServerState(), app_state={}, _loop=loop
        )
        for name in ("connections", "cycle", "loop", "on_response_complete", "data_received"):
            assert hasattr(protocol, name), name
        assert "self.transport = transport" in inspect.getsource(protocol.connection_made)
    finally:
        loop.close()


def test_the_websocket_protocol_counts_a_handshake_as_the_quiet_denials_expect() -> None:
    from uvicorn.protocols.websockets.auto import AutoWebSocketsProtocol

    assert AutoWebSocketsProtocol is not None
    assert "handshake_complete" in inspect.getsource(AutoWebSocketsProtocol)
