"""``ServerSet.stop`` stops every server and saves the takes whatever fails first.

Before, the first server whose stop raised ended ``stop``: the servers after it kept their
ports and the recordings in progress were never saved.
"""

from __future__ import annotations

import logging
import socket
from pathlib import Path

import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, serve
from poppy_core.motion import read_move
from tests.helpers.waiting import eventually


def _refused(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=2).close()
    except OSError:
        return True
    return False


def test_a_server_that_fails_to_stop_leaves_nothing_else_running(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    with from_profile("ergo-jr", sim=True) as robot:
        servers = serve(robot, ServeSpec(http=Listen(), ws=Listen()))
        http, ws = servers.http, servers.ws
        assert http is not None and ws is not None
        service = servers.service
        service.moves.record("take", ["m1"])
        assert eventually(lambda: len(service.moves.value("take")) > 5)

        def fail() -> None:
            raise RuntimeError("the WebSocket server would not stop")

        real_ws_stop = ws.stop
        monkeypatch.setattr(ws, "stop", fail)
        with caplog.at_level(logging.WARNING, logger="poppy_core"):
            servers.stop()
        assert not http.running and _refused(http.port)
        assert [t.name for t in service.moves.saved_on_close] == ["take"]
        assert len(read_move(tmp_path / "library" / "take.move")) > 5
        warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
        assert sum("the ws server failed" in w for w in warnings) == 1, warnings
        servers.stop()  # again: nothing
        real_ws_stop()
