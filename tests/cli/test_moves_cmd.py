"""`poppy moves list|show|plot|rm|export|import` on a temporary library (run in-process)."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from poppy_cli.main import app
from poppy_core.errors import ConfigError
from poppy_core.motion import Move, read_move, save_move
from tests.helpers.cli import keyed, run_poppy


@dataclass
class Result:
    code: int
    stdout: str
    error: BaseException | None

    def json(self) -> Any:
        return json.loads(self.stdout)


@pytest.fixture
def poppy() -> Callable[..., Result]:
    """``poppy ARGS`` in this process; a PoppyError is kept in ``error`` (the CLI exits 1)."""
    runner = CliRunner()

    def run(*args: str, input: str | None = None) -> Result:
        result = runner.invoke(app, list(args), input=input, env={"COLUMNS": "200"})
        error = result.exception if not isinstance(result.exception, SystemExit) else None
        return Result(result.exit_code, result.stdout, error)

    return run


@pytest.fixture(autouse=True)
def library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "moves"
    monkeypatch.setenv("POPPY_MOVES_DIR", str(folder))
    return folder


def wave() -> Move:
    t = np.arange(51) / 50
    return Move(
        50,
        ["m1", "m2"],
        np.column_stack([30 * np.sin(2 * np.pi * t), 10 * t]),
        metadata={"robot": "ergo-jr"},
    )


def test_list_and_show(poppy: Any, library: Path) -> None:
    empty = poppy("moves", "list")
    assert empty.code == 0 and "no move" in empty.stdout
    save_move(wave(), "wave")
    listed = poppy("moves", "list", "--json")
    assert listed.code == 0, listed.error
    data = listed.json()
    assert data["folder"] == str(library)
    (entry,) = data["moves"]
    assert entry["name"] == "wave" and entry["frames"] == 51 and entry["motors"] == ["m1", "m2"]
    assert "wave" in poppy("moves", "list").stdout
    shown = poppy("moves", "show", "wave", "--json").json()
    assert shown["duration_s"] == 1.0 and shown["metadata"]["robot"] == "ergo-jr"
    stats = keyed(shown["stats"])
    assert stats["m1"]["max"] == pytest.approx(30, abs=0.1)
    assert stats["m2"]["end"] == pytest.approx(10)
    table = poppy("moves", "show", "wave")
    assert table.code == 0 and "51 frames at 50 Hz" in table.stdout and "m2" in table.stdout


def test_export_both_formats_and_import_back(poppy: Any, tmp_path: Path) -> None:
    save_move(wave(), "wave")
    out = tmp_path / "wave.json"
    result = poppy("moves", "export", "wave", "-o", str(out), "--format", "pypot", "--json")
    assert result.code == 0, result.error
    document = json.loads(out.read_text())
    assert document["framerate"] == 50.0 and len(document["positions"]) == 51
    assert document["positions"]["0.02"]["m2"] == [pytest.approx(0.2), 0.0]
    ours = tmp_path / "wave.bin"
    assert poppy("moves", "export", "wave", "-o", str(ours), "--format", "poppy").code == 0
    assert read_move(ours).same_as(wave(), 1e-4)
    bad = poppy("moves", "export", "wave", "-o", str(ours), "--format", "yaml")
    assert bad.code == 2

    imported = poppy("moves", "import", str(out), "--name", "again", "--json")
    assert imported.code == 0, imported.error
    assert imported.json()["frames"] == 51
    assert read_move(imported.json()["path"]).same_as(wave(), 1e-4)
    clash = poppy("moves", "import", str(out), "--name", "again")
    assert isinstance(clash.error, ConfigError) and "exists" in str(clash.error)
    assert poppy("moves", "import", str(out), "--name", "again", "--force").code == 0


def test_rm_asks_first(poppy: Any, library: Path) -> None:
    save_move(wave(), "wave")
    refused = run_poppy("moves", "rm", "wave", input="y\n")  # stdin is no terminal: not asked
    assert refused.code == 2 and (library / "wave.move").exists()
    assert refused.stderr.strip() == (
        "error: not deleted: stdin is not a terminal to ask on; pass --yes"
    )
    assert poppy("moves", "rm", "wave", "--yes", "--json").json()["deleted"].endswith("wave.move")
    missing = poppy("moves", "rm", "wave", "--yes")
    assert isinstance(missing.error, ConfigError) and "no move 'wave'" in str(missing.error)


def test_plot_writes_a_png(poppy: Any, tmp_path: Path) -> None:
    save_move(wave(), "wave")
    image = tmp_path / "plots" / "wave.png"
    refused = poppy("moves", "plot", "wave", "-o", str(image))
    assert refused.code == 1 and "does not exist" in str(refused.error)  # no folder made for you
    image.parent.mkdir()
    result = poppy("moves", "plot", "wave", "-o", str(image))
    assert result.code == 0, result.error
    assert image.read_bytes().startswith(b"\x89PNG") and image.stat().st_size > 5000
