"""`poppy emulate`, `poppy scan`, `poppy ports` and `poppy demo` run as a user runs them."""

from __future__ import annotations

import signal
from typing import Any


def test_emulate_prints_the_pty_path_first_and_exits_0_on_sigterm(emulator_factory: Any) -> None:
    emulator = emulator_factory("--motors", "XL-320:1-2")
    assert emulator.url.startswith("/dev/")
    assert emulator.stop(signal.SIGTERM) == 0


def test_emulate_tcp_prints_a_socket_url(poppy: Any, emulator_factory: Any) -> None:
    emulator = emulator_factory("--motors", "XL-320:1-2", "--tcp", "127.0.0.1:0")
    assert emulator.url.startswith("socket://127.0.0.1:")
    found = poppy("scan", "--port", emulator.url, "--protocol", "2", "--json").json()
    assert [m["id"] for m in found] == [1, 2]


def test_scan_json_finds_exactly_the_ergo_jr(poppy: Any, ergo_jr: Any) -> None:
    result = poppy("scan", "--port", ergo_jr.url, "--json")
    assert result.code == 0, result.stderr
    found = result.json()
    assert [m["id"] for m in found] == [1, 2, 3, 4, 5, 6]
    assert set(found[0]) == {"port", "baud", "protocol", "id", "model", "model_number", "firmware"}
    assert {(m["model"], m["protocol"], m["baud"], m["model_number"]) for m in found} == {
        ("XL-320", 2, 1_000_000, 350)
    }


def test_scan_table_shows_models(poppy: Any, mx_bus: Any) -> None:
    result = poppy("scan", "--port", mx_bus.url, "--protocol", "1")
    assert result.code == 0, result.stderr
    assert "MX-28" in result.stdout and "AX-12A" in result.stdout
    assert "4 motors found" in result.stdout


def test_scan_with_nothing_answering_is_one_line_and_exit_1(poppy: Any, ergo_jr: Any) -> None:
    result = poppy("scan", "--port", ergo_jr.url, "--baud", "57600", "--protocol", "2")
    assert result.code == 1
    assert "no motor answered" in result.stderr
    assert "or try --all-bauds" in result.stderr
    assert "Traceback" not in result.stderr


def test_scan_of_every_rate_with_nothing_answering_does_not_advise_every_rate(
    poppy: Any, ergo_jr: Any
) -> None:
    result = poppy("scan", "--port", ergo_jr.url, "--all-bauds", "--protocol", "1", "--ids", "1")
    assert result.code == 1
    assert result.stderr.count("\n") == 1, result.stderr
    assert "no motor answered" in result.stderr
    assert "all standard rates" in result.stderr
    assert "--all-bauds" not in result.stderr


def test_scan_all_bauds_finds_a_motor_at_another_rate(poppy: Any, emulator_factory: Any) -> None:
    emulator = emulator_factory("--motors", "AX-12A:5", "--baud", "57600")
    result = poppy("scan", "--port", emulator.url, "--all-bauds", "--protocol", "1", "--json")
    assert result.code == 0, result.stderr
    assert [(m["id"], m["baud"]) for m in result.json()] == [(5, 57600)]


def test_scan_bad_port_is_one_line(poppy: Any, tmp_path: Any) -> None:
    result = poppy("scan", "--port", str(tmp_path / "ttyUSB9"))
    assert result.code == 1
    assert result.stderr.strip().count("\n") == 0
    assert "no such port" in result.stderr


def test_scan_bad_ids_is_a_usage_error(poppy: Any) -> None:
    result = poppy("scan", "--ids", "0-300", "--port", "loop://")
    assert result.code == 2
    assert "0-253" in result.stderr


def test_debug_shows_the_traceback(poppy: Any, tmp_path: Any) -> None:
    result = poppy("--debug", "scan", "--port", str(tmp_path / "ttyUSB9"))
    assert result.code != 0
    assert "Traceback" in result.stderr


def test_ports_json_is_a_list(poppy: Any) -> None:
    result = poppy("ports", "--json")
    assert result.code == 0
    assert isinstance(result.json(), list)


def test_demo_finds_the_virtual_ergo_jr(poppy: Any) -> None:
    result = poppy("demo")
    assert result.code == 0, result.stderr
    assert "6 motors found" in result.stdout
    assert "XL-320" in result.stdout


def test_emulate_needs_profile_or_motors(poppy: Any) -> None:
    result = poppy("emulate")
    assert result.code == 2
    assert "--profile" in result.stderr


def test_emulate_unknown_model_is_one_line(poppy: Any) -> None:
    result = poppy("emulate", "--motors", "FOO:1")
    assert result.code == 1
    assert "unknown model 'FOO'" in result.stderr
    assert "Traceback" not in result.stderr
