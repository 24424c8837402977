"""Tab completion of values (profiles, ports, moves, registers, primitives) through Typer's bash
completion: what the shell asks (COMP_WORDS, COMP_CWORD) and what `poppy` answers."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.bus.ports import PortInfo
from tests.helpers.cli import ENV, run_poppy

ROOT = Path(__file__).resolve().parents[2]


def complete(line: str, env: dict[str, str] | None = None) -> list[str]:
    """What bash completion offers for the last word of ``line`` (a trailing space: a new word)."""
    words = [*shlex.split(line), *([""] if line.endswith(" ") else [])]
    result = run_poppy(
        env={
            "_POPPY_COMPLETE": "complete_bash",
            "COMP_WORDS": " ".join(words),
            "COMP_CWORD": str(len(words) - 1),
            **(env or {}),
        }
    )
    assert result.code == 0, result.stderr
    return result.stdout.split()


@pytest.fixture(autouse=True)
def no_settings(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("POPPY_PROFILE", raising=False)
    monkeypatch.delenv("POPPY_PORT", raising=False)


def test_profile_names() -> None:
    assert {"ergo-jr", "torso", "humanoid"} <= set(complete("poppy robot status --profile "))
    assert complete("poppy record wave --profile er") == ["ergo-jr"]
    assert "torso" in complete("poppy config show ")
    assert "humanoid" in complete("poppy teleop --leader ergo-jr --follower h")


def test_serial_ports_are_listed_not_opened(monkeypatch: pytest.MonkeyPatch) -> None:
    import serial

    from poppy_core.bus import ports

    fake = [PortInfo("/dev/ttyACM0", "USB2AX", adapter="USB2AX"), PortInfo("/dev/ttyS0", "UART")]
    monkeypatch.setattr(ports, "list_ports", lambda **_: fake)

    def refuse(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("completion opened a port")

    monkeypatch.setattr(serial, "Serial", refuse)
    monkeypatch.setattr(serial, "serial_for_url", refuse)
    assert complete("poppy scan --port ") == ["/dev/ttyACM0", "/dev/ttyS0"]
    assert complete("poppy motor get 3 present_position -p /dev/ttyA") == ["/dev/ttyACM0"]
    assert complete("poppy teleop --leader-port /dev/ttyS") == ["/dev/ttyS0"]


def test_move_names_of_the_library(tmp_path: Path) -> None:
    from poppy_core.motion import Move, save_move

    library = tmp_path / "moves"
    library.mkdir()
    for name in ("wave", "walk", "dance"):
        save_move(Move(10, ["m1"], np.zeros((3, 1))), library / f"{name}.move")
    env = {"POPPY_MOVES_DIR": str(library)}
    assert complete("poppy play ", env) == ["dance", "walk", "wave"]
    assert complete("poppy play wa", env) == ["walk", "wave"]
    assert complete("poppy moves rm d", env) == ["dance"]
    assert complete("poppy sim render --move w", env) == ["walk", "wave"]
    assert complete("poppy play ./w", env) == []  # a path: the shell completes files


def test_register_names() -> None:
    assert "present_position" in complete("poppy motor get 3 present_p")
    assert "goal_position" in complete("poppy motor get 3 present_position g")
    writable = complete("poppy motor set 3 ")
    assert "goal_position" in writable and "present_position" not in writable


def test_primitive_names_of_the_robot_or_the_builtins() -> None:
    builtins = {"sinus", "cosinus", "square", "position_watcher", "simple_posture"}
    assert set(complete("poppy primitive run ")) == builtins
    ergo = set(complete("poppy primitive run --profile ergo-jr "))
    assert builtins | {"dance", "jump", "rest_posture"} <= ergo
    assert complete("poppy primitive run --profile torso temp") == ["temperature_monitoring"]
    assert "dance" in complete("poppy primitive run ", {"POPPY_PROFILE": "ergo-jr"})


def test_small_choices() -> None:
    assert complete("poppy robot compliant ") == ["on", "off"]
    assert complete("poppy motor torque 1-6 o") == ["on", "off"]
    assert complete("poppy robot status --sim m") == ["mujoco"]
    assert complete("poppy teleop --follower ergo-jr --follower-sim ") == ["mujoco", "ideal"]


def test_an_unknown_profile_still_gives_the_builtins() -> None:
    assert complete("poppy primitive run --profile no-such-robot ") == [
        "sinus",
        "cosinus",
        "square",
        "position_watcher",
        "simple_posture",
    ]


def test_completion_in_a_shell_process_loads_no_heavy_library(tmp_path: Path) -> None:
    """As bash runs it: a new process, the words in the environment; quick and lazy."""
    code = (
        "import sys\nfrom poppy_cli.main import main\n"
        "try:\n    main()\nexcept SystemExit:\n    pass\n"
        "print('MODULES', *sorted({m.split('.')[0] for m in sys.modules}), file=sys.stderr)\n"
    )
    for line in ("poppy primitive run --profile ergo-jr ", "poppy play ", "poppy scan -p "):
        words = [*shlex.split(line), ""]
        env = dict(
            os.environ,
            **ENV,
            _POPPY_COMPLETE="complete_bash",
            COMP_WORDS=" ".join(words),
            COMP_CWORD=str(len(words) - 1),
            PYTHONPATH=str(ROOT),
            POPPY_MOVES_DIR=str(tmp_path),
        )
        proc = subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            env=env,
            timeout=60,
            cwd=ROOT,
        )
        modules = set(proc.stderr.split("MODULES", 1)[1].split())
        assert not modules & {"mujoco", "fastapi", "uvicorn", "textual", "cv2", "matplotlib"}
        if "primitive" in line:
            assert "dance" in proc.stdout.split()
