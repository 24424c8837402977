"""`poppy emulate` fault injection: --unplug, --drop, --link and commands on stdin (--control)."""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path
from typing import Any

from tests.helpers.cli import POPPY
from tests.helpers.waiting import eventually, scaled


def _ids(poppy: Any, port: str) -> list[int]:
    result = poppy("scan", "--port", port, "--protocol", "2", "--ids", "1-3", "--json")
    assert result.code in (0, 1), result.stderr
    return [m["id"] for m in result.json()] if result.code == 0 else []


def test_unplug_at_start_and_link(poppy: Any, emulator_factory: Any, tmp_path: Path) -> None:
    link = tmp_path / "ttyDXL"
    emulator = emulator_factory("--motors", "XL-320:1-3", "--unplug", "2@0", "--link", str(link))
    assert emulator.url == str(link)
    assert os.readlink(link).startswith("/dev/")
    assert _ids(poppy, str(link)) == [1, 3]


def test_drop_everything_means_silence(poppy: Any, emulator_factory: Any) -> None:
    emulator = emulator_factory("--motors", "XL-320:1-3", "--drop", "1")
    assert _ids(poppy, emulator.url) == []


def test_commands_on_stdin(poppy: Any) -> None:
    proc = subprocess.Popen(
        [*POPPY, "emulate", "--motors", "XL-320:1-3", "--control"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None and proc.stdin is not None
        url = proc.stdout.readline().strip()
        assert _ids(poppy, url) == [1, 2, 3]
        proc.stdin.write("unplug 1\nbogus\n")
        proc.stdin.flush()
        # the emulator process reads its stdin when a busy machine runs it
        assert eventually(lambda: _ids(poppy, url) == [2, 3])
    finally:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=scaled(10))
    assert proc.returncode == 0
    assert "motor 1 unplugged" in err
    assert "unknown command 'bogus'" in err


def test_bad_fault_options_are_usage_errors(poppy: Any) -> None:
    result = poppy("emulate", "--motors", "XL-320:1", "--unplug", "two@3")
    assert result.code == 2
    assert "ID@SECONDS" in result.stderr and "Traceback" not in result.stderr
    result = poppy("emulate", "--motors", "XL-320:1", "--unplug", "5@1")
    assert result.code == 2
    assert "no motor 5" in result.stderr
    result = poppy("emulate", "--motors", "XL-320:1", "--drop", "2")
    assert result.code == 2
    result = poppy("emulate", "--motors", "XL-320:1", "--tcp", "127.0.0.1:0", "--link", "/tmp/x")
    assert result.code == 2
    assert "--link" in result.stderr
