"""Exit codes and defaults: a refused file is 1, Ctrl-C is 130, `scan` says which port it
chose and why, a mistyped profile gets a suggestion, counts are English."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

from poppy_core.bus.ports import PortInfo
from tests.cli.conftest import LinkedBus
from tests.helpers.cli import run_poppy
from tests.helpers.terminal import Terminal

ROOT = Path(__file__).resolve().parents[2]


def test_ctrl_c_ends_robot_status_watch_with_130() -> None:
    terminal = Terminal("robot", "status", "--sim", "--profile", "ergo-jr", "--watch")
    try:
        assert "Ctrl-C to stop" in terminal.read_until("Ctrl-C to stop")
        terminal.signal(signal.SIGINT)
        assert terminal.wait() == 130
    finally:
        terminal.close()


def _ports(monkeypatch: pytest.MonkeyPatch, *ports: PortInfo) -> None:
    monkeypatch.delenv("POPPY_PORT", raising=False)
    monkeypatch.setattr("poppy_core.bus.ports.list_ports", lambda **_: list(ports))


def test_scan_without_port_prefers_a_recognised_adapter_and_says_so(
    monkeypatch: pytest.MonkeyPatch, ergo_jr: LinkedBus
) -> None:
    uart = PortInfo("/dev/ttyS0", "ttyS0")
    u2d2 = PortInfo(ergo_jr.url, "USB <-> Serial", 0x0403, 0x6014, adapter="U2D2")
    _ports(monkeypatch, uart, u2d2)
    result = run_poppy("scan", "--ids", "1-6", "--protocol", "2", "--json")
    assert result.code == 0, result.stderr
    assert {m["port"] for m in result.json()} == {ergo_jr.url}
    assert f"scanning {ergo_jr.url} (U2D2, 0403:6014)" in result.stderr
    assert (
        "a recognised Dynamixel adapter; 1 other port skipped" in result.stderr
        and "--port" in result.stderr
    )


def test_scan_names_the_only_port_it_falls_back_to(monkeypatch: pytest.MonkeyPatch) -> None:
    _ports(monkeypatch, PortInfo("loop://", "a built-in UART"))
    result = run_poppy("scan", "--ids", "1", "--protocol", "1")
    assert result.code == 1  # no motor answered there
    assert "scanning loop:// (a built-in UART), the only serial port" in result.stderr
    assert "not a recognised Dynamixel adapter" in result.stderr


def test_scan_refuses_to_guess_among_unrecognised_ports(monkeypatch: pytest.MonkeyPatch) -> None:
    _ports(monkeypatch, PortInfo("/dev/ttyS0", "ttyS0"), PortInfo("/dev/ttyACM0", "Arduino"))
    result = run_poppy("scan")  # stdin is not a terminal: nothing asked
    assert result.code == 2
    assert "/dev/ttyS0 (ttyS0)" in result.stderr and "/dev/ttyACM0 (Arduino)" in result.stderr
    assert "--port" in result.stderr and len(result.stderr.splitlines()) == 1


def test_scan_asks_which_unrecognised_port_on_a_terminal(
    monkeypatch: pytest.MonkeyPatch, ergo_jr: LinkedBus
) -> None:
    _ports(monkeypatch, PortInfo("/dev/ttyS0", "ttyS0"), PortInfo(ergo_jr.url, "a hub"))
    asked: list[str] = []
    monkeypatch.setattr(
        "poppy_cli.port_choice.ask", lambda question, **_: asked.append(question) or "2"
    )
    result = run_poppy("scan", "--ids", "1-6", "--protocol", "2", "--json")
    assert result.code == 0, result.stderr
    assert "Which one" in asked[0] and "/dev/ttyS0" in asked[0]
    assert len(result.json()) == 6


@pytest.mark.parametrize(("typed", "meant"), [("ergo-jt", "ergo-jr"), ("tors", "torso")])
def test_a_mistyped_profile_gets_a_suggestion(typed: str, meant: str) -> None:
    result = run_poppy("robot", "status", "--sim", "--profile", typed)
    assert result.code == 1
    assert f"did you mean {meant}?" in result.stderr


def test_counts_are_singular_for_one() -> None:
    result = run_poppy("config", "validate", str(ROOT / "profiles" / "ergo-jr" / "profile.yaml"))
    assert result.code == 0, result.stderr
    assert "6 motors, 1 controller, 2 groups" in result.stdout


@pytest.mark.parametrize("command", ["record", "teleop"])
def test_a_take_that_would_replace_a_move_is_refused_with_1(
    command: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path, ergo_jr: LinkedBus
) -> None:
    from poppy_core.motion import Move, save_move

    monkeypatch.setenv("POPPY_MOVES_DIR", str(tmp_path))
    save_move(Move.from_frames(50.0, [{"m1": 0.0}, {"m1": 1.0}]), "taken")
    args = {
        "record": ("record", "taken", "--sim", "--profile", "ergo-jr", "--duration", "0.2"),
        "teleop": (
            "teleop",
            "--leader",
            "ergo-jr",
            "--leader-port",
            ergo_jr.url,
            "--follower",
            "ergo-jr",
            "--follower-port",
            ergo_jr.url,
            "--record",
            "taken",
        ),
    }[command]
    result = run_poppy(*args)
    assert result.code == 1, result.stderr
    assert "exists" in result.stderr and "--force" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1  # one line, nothing unexpected


def test_one_motor_found_is_singular(ergo_jr: LinkedBus) -> None:
    result = run_poppy("scan", "--port", ergo_jr.url, "--protocol", "2", "--ids", "3")
    assert result.code == 0, result.stderr
    assert "1 motor found" in result.stdout
