"""Commands that write files never clobber: --force to replace, never a non-regular file."""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.motion import Move, save_move

DATA = Path(__file__).resolve().parents[1] / "robot" / "data"
ERGO_JSON = DATA / "poppy_ergo_jr.json"


@pytest.fixture(autouse=True)
def library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "moves"
    monkeypatch.setenv("POPPY_MOVES_DIR", str(folder))
    save_move(Move(50, ["m1"], np.linspace(0, 10, 20)[:, None]), "wave")
    return folder


def one_line(result: Any) -> str:
    assert result.code == 1, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "unexpected" not in lines[0]
    return lines[0]


# Each command writing a file, as (arguments before the output, how the output is given).
WRITERS = {
    "moves export": (("moves", "export", "wave", "-o"), ".json"),
    "moves plot": (("moves", "plot", "wave", "-o"), ".png"),
    "config convert": (("config", "convert", str(ERGO_JSON)), ".yaml"),
}


def _run(poppy: Any, writer: str, target: Path, *extra: str) -> Any:
    args, _ = WRITERS[writer]
    return poppy(*args, str(target), *extra)


@pytest.mark.parametrize("writer", WRITERS)
def test_an_existing_file_needs_force(poppy: Any, tmp_path: Path, writer: str) -> None:
    target = tmp_path / f"out{WRITERS[writer][1]}"
    target.write_text("mine")
    line = one_line(_run(poppy, writer, target))
    assert f"{target} already exists: pass --force" in line
    assert target.read_text() == "mine"
    result = _run(poppy, writer, target, "--force")
    assert result.code == 0, result.stderr
    assert target.read_bytes() != b"mine"


@pytest.mark.parametrize("writer", WRITERS)
def test_a_fifo_is_never_written(poppy: Any, tmp_path: Path, writer: str) -> None:
    fifo = tmp_path / f"pipe{WRITERS[writer][1]}"
    os.mkfifo(fifo)
    for extra in ((), ("--force",)):
        assert "is a FIFO" in one_line(_run(poppy, writer, fifo, *extra))  # and no hang
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


@pytest.mark.parametrize("writer", WRITERS)
def test_a_symlink_is_never_followed_or_replaced(poppy: Any, tmp_path: Path, writer: str) -> None:
    precious = tmp_path / "precious.txt"
    precious.write_text("precious")
    link = tmp_path / f"link{WRITERS[writer][1]}"
    link.symlink_to(precious)
    assert "symbolic link" in one_line(_run(poppy, writer, link, "--force"))
    assert link.is_symlink() and precious.read_text() == "precious"


@pytest.mark.skipif(os.geteuid() != 0 or not Path("/dev/full").exists(), reason="needs root")
@pytest.mark.parametrize("writer", WRITERS)
def test_dev_full_stays_a_device(poppy: Any, writer: str) -> None:
    assert "character device" in one_line(_run(poppy, writer, Path("/dev/full"), "--force"))
    assert stat.S_ISCHR(os.lstat("/dev/full").st_mode)


@pytest.mark.parametrize("writer", WRITERS)
def test_a_missing_folder_is_not_created(poppy: Any, tmp_path: Path, writer: str) -> None:
    target = tmp_path / "missing" / f"out{WRITERS[writer][1]}"
    assert "does not exist: create it first" in one_line(_run(poppy, writer, target))
    assert not target.parent.exists()


def test_a_folder_receives_a_file_named_after_the_source(poppy: Any, tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    assert poppy("moves", "export", "wave", "-o", str(out)).code == 0
    assert (out / "wave.move").read_bytes().startswith(b"POPPYMOV")
    assert poppy("moves", "export", "wave", "-o", str(out), "--format", "pypot").code == 0
    assert json.loads((out / "wave.json").read_text())["framerate"] == 50
    assert poppy("moves", "plot", "wave", "-o", str(out)).code == 0
    assert (out / "wave.png").read_bytes().startswith(b"\x89PNG")
    assert poppy("config", "convert", str(ERGO_JSON), str(out)).code == 0
    assert "motors:" in (out / "poppy_ergo_jr.yaml").read_text()
    again = poppy("moves", "export", "wave", "-o", str(out))
    assert "already exists" in one_line(again)


def test_saved_files_get_the_umask(poppy: Any, tmp_path: Path) -> None:
    old = os.umask(0o002)  # inherited by the child process
    try:
        assert poppy("moves", "export", "wave", "-o", str(tmp_path / "w.json")).code == 0
        assert poppy("config", "convert", str(ERGO_JSON), str(tmp_path / "r.yaml")).code == 0
        assert poppy("moves", "import", str(tmp_path / "w.json"), "--name", "w2").code == 0
    finally:
        os.umask(old)
    for path in (tmp_path / "w.json", tmp_path / "r.yaml", tmp_path / "moves" / "w2.move"):
        assert stat.S_IMODE(path.stat().st_mode) == 0o664, path


def test_sim_render_refuses_before_rendering(poppy: Any, tmp_path: Path) -> None:
    target = tmp_path / "robot.png"
    target.write_text("mine")
    assert "already exists" in one_line(poppy("sim", "render", "-o", str(target)))
    assert target.read_text() == "mine"
