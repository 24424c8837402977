"""A server stopping keeps the takes not saved yet: recordings in progress (REST, Snap!) and a
take kept after a failed save go to the move library, or to a temporary file when the library
cannot have them, and ``poppy serve`` says where on stderr (as ``poppy record`` does)."""

from __future__ import annotations

import errno
import os
import signal
import sys
import tempfile
from pathlib import Path

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.errors import FileError
from poppy_core.motion import read_move
from poppy_core.server import moves as moves_module
from poppy_core.server.errors import ApiError
from poppy_core.server.moves import MoveService
from tests.helpers.cli import command_env
from tests.helpers.processes import reap, start
from tests.helpers.waiting import eventually, http_timeout

POPPY = [sys.executable, "-m", "poppy_cli"]
WAIT_S = 60.0


def test_sigterm_saves_the_rest_and_snap_recordings_and_says_where(tmp_path: Path) -> None:
    library, temp = tmp_path / "library", tmp_path / "tmp"
    library.mkdir()
    temp.mkdir()
    (library / "taken.move").write_text("a move of that name is already saved\n")
    env = dict(
        os.environ,
        **command_env({"COLUMNS": "300"}),
        POPPY_MOVES_DIR=str(library),
        TMPDIR=str(temp),
    )
    proc = start(
        [
            *POPPY,
            "serve",
            "--http",
            "--http-port",
            "0",
            "--snap",
            "--snap-port",
            "0",
            "--sim",
            "--profile",
            "ergo-jr",
        ],
        env,
    )
    try:
        assert proc.stdout is not None and proc.stderr is not None
        http = proc.stdout.readline().strip()  # the URL alone, then "docs: …", "snap: …"
        assert http.startswith("http://127.0.0.1:")
        proc.stdout.readline()
        snap = proc.stdout.readline().strip().removeprefix("snap: ")
        with httpx.Client(timeout=http_timeout(10.0)) as client:
            answer = client.post(f"{http}/records/rest_take/record.json", json={"motors": "m1"})
            assert answer.status_code == 202, answer.text
            assert client.post(f"{http}/records/taken/record.json").status_code == 202
            answer = client.get(f"{snap}/primitive/MoveRecorder/snap_take/start")
            assert answer.status_code == 200, answer.text

            def frames(name: str) -> int:
                value = client.get(f"{http}/records/{name}/value.json").json()
                return int(value["length"])

            for name in ("rest_take", "taken", "snap_take"):
                assert eventually(lambda name=name: frames(name) > 5, WAIT_S)  # type: ignore[misc]
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=WAIT_S) == 0
        errors = proc.stderr.read()
    finally:
        reap(proc)
    assert "stopped" in errors
    for name in ("rest_take", "snap_take"):
        saved = library / f"{name}.move"
        assert len(read_move(saved)) > 5
        assert f"the take '{name}'" in errors and str(saved) in errors
    assert (library / "taken.move").read_text() == "a move of that name is already saved\n"
    (elsewhere,) = temp.glob("poppy-take-taken-*.move")
    assert len(read_move(elsewhere)) > 5
    assert str(elsewhere) in errors and f"poppy moves import {elsewhere}" in errors


def test_a_take_kept_after_a_failed_save_is_saved_on_closing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path / "library"))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))

    def full(*args: object, **kwargs: object) -> Path:
        raise FileError("cannot write kept.move: no space left on the device", errno=errno.ENOSPC)

    with from_profile("ergo-jr", sim=True) as robot:
        service = MoveService(robot)
        service.record("kept", ["m1"])
        assert eventually(lambda: len(service.value("kept")) > 5)
        monkeypatch.setattr(moves_module, "save_move", full)
        with pytest.raises(ApiError):
            service.save("kept")  # 507: kept in memory
        kept = service.value("kept")
        saved = service.close()  # the library is still full: a temporary file
        assert service.close() == []  # once
    assert [(t.name, t.in_library, t.frames) for t in saved] == [("kept", False, len(kept))]
    assert saved[0].path.parent == tmp_path and saved[0].path.name.startswith("poppy-take-kept-")
    assert read_move(saved[0].path).same_as(kept, tolerance_deg=1e-3)
    assert service.saved_on_close == saved


def test_closing_with_nothing_recorded_saves_nothing(tmp_path: Path) -> None:
    with from_profile("ergo-jr", sim=True) as robot:
        service = MoveService(robot)
        assert service.close() == []
