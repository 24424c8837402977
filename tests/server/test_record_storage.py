"""A recording the server cannot save (full disk) answers 507 and is kept for a later save."""

from __future__ import annotations

import errno
import os
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.errors import FileError
from poppy_core.motion import read_move
from poppy_core.server import moves as moves_module
from poppy_core.server.errors import ApiError
from poppy_core.server.moves import MoveService
from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout


def test_a_failed_save_keeps_the_recording(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path))
    real_save = moves_module.save_move

    def full(*args: object, **kwargs: object) -> Path:
        raise FileError("cannot write wave.move: no space left on the device", errno=errno.ENOSPC)

    with from_profile("ergo-jr", sim=True) as robot:
        service = MoveService(robot)
        service.record("wave", ["m1"])
        time.sleep(0.2)
        monkeypatch.setattr(moves_module, "save_move", full)
        with pytest.raises(ApiError) as caught:
            service.save("wave")
        assert caught.value.kind == "storage" and "it is kept" in caught.value.message
        assert service.recording() == ["wave"]
        kept = service.value("wave")
        assert len(kept) > 0
        monkeypatch.setattr(moves_module, "save_move", real_save)
        saved = service.save("wave")
        assert saved.same_as(kept)
        assert service.recording() == []
        service.close()
    assert read_move(tmp_path / "wave.move").same_as(kept, tolerance_deg=1e-3)


@pytest.fixture
def full_library(tmp_path: Path) -> Iterator[Path]:
    """A 32 kB tmpfs, full, as the move library (root only)."""
    folder = tmp_path / "full"
    folder.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    if (
        subprocess.run(
            ["mount", "-t", "tmpfs", "-o", "size=32k", "tmpfs", str(folder)], capture_output=True
        ).returncode
        != 0
    ):
        pytest.skip("cannot mount a tmpfs")
    (folder / "filler").write_bytes(b"\0" * 30_000)  # all 8 pages of the tmpfs
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)


def test_rest_save_on_a_full_disk_is_507_then_works(
    full_library: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("POPPY_MOVES_DIR", str(full_library))
    server = serve(str(full_library))
    served: Served = next(server)
    try:
        with httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as client:
            assert client.post("/api/v1/moves/wave/record", json={}).status_code == 202
            time.sleep(1)
            answer = client.post("/api/v1/moves/wave/save")
            assert answer.status_code == 507, answer.text
            assert "no space left" in answer.json()["detail"]
            assert client.get("/api/v1/moves/status").json()["recording"] == ["wave"]
            pypot = client.post("/records/wave/save.json")
            assert pypot.status_code == 507
            (full_library / "filler").unlink()
            answer = client.post("/api/v1/moves/wave/save")
            assert answer.status_code == 200, answer.text
            assert answer.json()["frames"] > 30
    finally:
        server.close()
    assert len(read_move(full_library / "wave.move")) > 30
