"""Piped output (stdout not a terminal) is whole lines at the data's width: never cut to the
terminal's width, never a value split over two lines, a live display ended by a newline."""

from __future__ import annotations

import os
import subprocess

import pytest

from tests.cli.conftest import LinkedBus
from tests.helpers import cli
from tests.helpers.cli import POPPY, run_poppy
from tests.helpers.waiting import reply_floor_env, scaled


@pytest.fixture
def narrow(monkeypatch: pytest.MonkeyPatch) -> None:
    """The in-process `poppy` gets a 40-column console, as a narrow terminal's COLUMNS."""
    monkeypatch.setattr(cli, "WIDTH", 40)


def _table_rows(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith(("│", "┃"))]


def test_robot_status_piped_is_not_cut_to_the_width(narrow: None) -> None:
    result = run_poppy("robot", "status", "--sim", "--profile", "ergo-jr")
    assert result.code == 0, result.stderr
    assert "…" not in result.stdout
    rows = _table_rows(result.stdout)
    for name in ("m1", "m6"):  # every motor on one line, from its name to its link
        (row,) = [r for r in rows if r.startswith(f"│ {name} ")]
        assert "°/s" in row and "°C" in row and row.rstrip().endswith("online │")
    (bus,) = [r for r in rows if "connected" in r]
    assert "present" in bus and "sensors" in bus  # the loops cell is not wrapped
    header = next(r for r in rows if "position" in r)
    assert "voltage" in header and "compliant" in header


def test_a_title_wider_than_its_table_stays_on_one_line(narrow: None, ergo_jr: LinkedBus) -> None:
    result = run_poppy("motor", "info", "3", "--port", ergo_jr.url)
    assert result.code == 0, result.stderr
    title = result.stdout.splitlines()[0]
    assert title.strip().startswith("motor 3: XL-320") and title.rstrip().endswith("protocol 2")
    assert "…" not in result.stdout


def test_demo_piped_ends_each_table_with_a_newline() -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
    env.update(reply_floor_env())
    proc = subprocess.run(
        [*POPPY, "demo", "--quick"], capture_output=True, text=True, timeout=scaled(120), env=env
    )
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert any(line.startswith("replayed ") for line in lines)
    for line in lines:  # a table's bottom border is a line of its own
        if "┘" in line:
            assert line.endswith("┘"), line
    assert not any("…" in row for row in _table_rows(proc.stdout))
    assert "virtual Ergo Jr dancing: replayed" in lines  # a title is not wrapped either
