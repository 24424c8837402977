"""pypot's own IO (``DxlIO``, ``Dxl320IO``, from the peers venv) against ``poppy emulate`` on a pty.

pypot 5.0.2 runs in its own interpreter (bench/.venv-peers, made by ``bash bench/setup_peers.sh``,
which CI runs first) as a subprocess: it scans, reads, writes and reads back, and the values it
sees are checked. Without the peers venv the tests skip, except in CI (``CI=true``), where its
absence is a failure.
"""

from __future__ import annotations

import json
import os
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.cli.conftest import Emulator

ROOT = Path(__file__).resolve().parents[2]
PEERS_PYTHON = ROOT / "bench" / ".venv-peers" / "bin" / "python"
CLIENT = Path(__file__).with_name("pypot_dxlio_client.py")
CLIENT_TIMEOUT_S = 180.0
GOAL_DEG = 20.0


def _peers_python() -> Path:
    usable = PEERS_PYTHON.exists() and (
        subprocess.run(
            [str(PEERS_PYTHON), "-c", "import pypot.dynamixel"], capture_output=True
        ).returncode
        == 0
    )
    if not usable:
        reason = f"no pypot in {PEERS_PYTHON}: run `bash bench/setup_peers.sh`"
        if os.environ.get("CI") == "true":
            pytest.fail(f"{reason} (CI runs it before the tests)")
        pytest.skip(reason)
    return PEERS_PYTHON


@pytest.fixture
def emulator(request: pytest.FixtureRequest) -> Iterator[Emulator]:
    emulator = Emulator(*request.param)
    yield emulator
    emulator.stop()


def _pypot(port: str, protocol: int, first: int, last: int) -> dict[str, Any]:
    done = subprocess.run(
        [
            str(_peers_python()),
            str(CLIENT),
            port,
            str(protocol),
            str(first),
            str(last),
            str(GOAL_DEG),
        ],
        capture_output=True,
        text=True,
        timeout=CLIENT_TIMEOUT_S,
    )
    lines = done.stdout.strip().splitlines()
    assert lines, f"pypot's client printed nothing; stderr: {done.stderr[-2000:]}"
    record: dict[str, Any] = json.loads(lines[-1])
    assert "error" not in record, f"pypot failed: {record['error']}; stderr: {done.stderr[-2000:]}"
    return record


def _check(record: dict[str, Any], ids: list[int], model: str, resolution_deg: float) -> None:
    assert record["found"] == ids
    assert record["models"] == [model] * len(ids)
    assert all(abs(p) < 180 for p in record["positions_before"])
    assert record["torque_on"] == [True] * len(ids)
    assert all(abs(g - GOAL_DEG) <= resolution_deg for g in record["goals"]), record["goals"]
    assert all(abs(p - GOAL_DEG) < 1.0 for p in record["positions_after"]), record
    assert record["torque_off"] == [False] * len(ids)


@pytest.mark.parametrize(
    "emulator", [("--motors", "MX-28:11-13", "--protocol", "1")], indirect=True
)
def test_pypot_dxlio_on_protocol_1(emulator: Emulator) -> None:
    record = _pypot(emulator.url, 1, 10, 14)
    _check(record, [11, 12, 13], "MX-28", 360 / 4096)


@pytest.mark.parametrize("emulator", [("--profile", "ergo-jr")], indirect=True)
def test_pypot_dxl320io_on_the_ergo_jr(emulator: Emulator) -> None:
    record = _pypot(emulator.url, 2, 1, 7)
    _check(record, [1, 2, 3, 4, 5, 6], "XL-320", 300 / 1024)
