"""Numbers and names at the edges: each is one clear line, never "unexpected ...", never a hang."""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from poppy_core.motion import Move, write_move
from tests.helpers.cli import no_user_settings

SIM = ("--sim", "--profile", "ergo-jr")


@pytest.fixture(autouse=True)
def library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    return no_user_settings(tmp_path, monkeypatch, moves=True)


def one_line(result: Any, code: int) -> str:
    assert result.code == code, (result.code, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ")
    assert "unexpected" not in lines[0] and "Traceback" not in result.stderr
    return lines[0]


@pytest.mark.parametrize("baud", ["0", "-5", "99999999999999999999", "10000000000"])
def test_baud_rates_out_of_range_are_usage_errors(poppy: Any, baud: str) -> None:
    for args in (
        ("scan", "--port", "loop://", "--baud", baud),
        ("motor", "get", "1", "id", "--port", "loop://", "--baud", baud),
    ):
        line = one_line(poppy(*args), 2)
        assert "--baud" in line


@pytest.mark.parametrize("duration", ["1e300", "nan", "inf", "-1"])
def test_durations_out_of_range_are_usage_errors(poppy: Any, duration: str) -> None:
    for args in (
        ("robot", "goto", "m1=10", *SIM, "--duration", duration),
        ("primitive", "run", "sinus", *SIM, "--duration", duration),
        ("record", "wave", *SIM, "--duration", duration),
    ):
        line = one_line(poppy(*args), 2)
        assert "--duration" in line


def test_play_speed_and_loops_out_of_range(poppy: Any) -> None:
    assert "--speed" in one_line(poppy("play", "wave", *SIM, "--speed", "nan"), 2)
    assert "--loop" in one_line(poppy("play", "wave", *SIM, "--loop", "10000000"), 2)


def test_a_300_character_move_name(poppy: Any) -> None:
    name = "a" * 300
    for args in (
        ("play", name, *SIM),
        ("record", name, *SIM, "--duration", "1"),
        ("moves", "show", name),
    ):
        line = one_line(poppy(*args), 1)
        assert "at most 100 characters" in line


def test_a_moves_dir_that_is_a_file(poppy: Any, library: Path) -> None:
    library.write_text("not a folder")
    for args in (
        ("moves", "list"),
        ("play", "wave", *SIM),
        ("record", "wave", *SIM),
        ("moves", "import", str(library)),
    ):
        line = one_line(poppy(*args), 1)
        assert f"{library}" in line


def test_a_move_without_frames(poppy: Any, library: Path) -> None:
    library.mkdir()
    write_move(Move(50, ["m1"], np.zeros((0, 1))), library / "empty.move")
    assert "no frame" in one_line(poppy("play", "empty", *SIM), 1)
    shown = poppy("moves", "show", "empty")
    assert shown.code == 0, shown.stderr
    assert "0 frames" in shown.stdout


def test_goto_beyond_the_angle_limits_is_clamped_as_everywhere(poppy: Any) -> None:
    result = poppy("robot", "goto", "m1=100000", "--duration", "0.2", *SIM)
    assert result.code == 0, result.stderr
    assert "(goal 150°)" in result.stdout  # the Ergo Jr's m1 limit: the answer says the clamp


class _Garbage(http.server.BaseHTTPRequestHandler):
    body = b"<html>not json</html>"

    def do_GET(self) -> None:
        self.send_response(200)
        self.end_headers()
        self.wfile.write(type(self).body)

    do_POST = do_GET

    def log_message(self, *args: Any) -> None:
        pass


class _WrongJson(_Garbage):
    body = b'{"robot": "not poppy"}'


@pytest.fixture(params=[_Garbage, _WrongJson])
def garbage_server(request: pytest.FixtureRequest) -> Iterator[str]:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), request.param)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_a_garbage_remote_server(poppy: Any, garbage_server: str) -> None:
    for args in (
        ("robot", "status"),
        ("play", "wave"),
        ("primitive", "list"),
        ("robot", "goto", "m1=1"),
    ):
        line = one_line(poppy(*args, "--remote", garbage_server), 1)
        assert "is not a poppy server" in line


@pytest.mark.parametrize("url", ["http://[::1", "http://127.0.0.1:99999", "garbage"])
def test_a_bad_remote_url(poppy: Any, url: str) -> None:
    line = one_line(poppy("robot", "status", "--remote", url), 1)
    assert "is not an http://host:port URL" in line


def test_unknown_primitive_property_lists_properties(poppy: Any) -> None:
    line = one_line(poppy("primitive", "run", "sinus", *SIM, "--set", "volume=3"), 1)
    assert "(properties: " in line and "propertys" not in line


def test_return_delay_out_of_range_says_nothing_first(poppy: Any, mx_bus: Any) -> None:
    result = poppy(
        "motor", "set-return-delay", "11", "--port", mx_bus.url, "--protocol", "1", "--", "-5"
    )
    line = one_line(result, 1)
    assert "return_delay_time" in line and "out of range" in line
    assert result.stdout == ""  # no "· motor 11: return delay -5.0 µs" progress line first


BOMB = (
    "\n".join(
        [f"a0: &a0 [{','.join(['lol'] * 9)}]"]
        + [f"a{i}: &a{i} [{','.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
        + ["controllers: {}", "motors: {}", "sensors: {s: {x: *a8}}"]
    )
    + "\n"
)


def test_config_validate_refuses_an_alias_bomb(poppy: Any, tmp_path: Path) -> None:
    path = tmp_path / "bomb.yaml"
    path.write_text(BOMB)
    line = one_line(poppy("config", "validate", str(path)), 1)
    assert "values once YAML aliases are expanded" in line


def test_config_validate_refuses_deep_documents(poppy: Any, tmp_path: Path) -> None:
    for name, text in (
        ("deep.json", "[" * 100_000 + "]" * 100_000),
        ("deep.yaml", "a: " + "[" * 100_000 + "]" * 100_000),
    ):
        path = tmp_path / name
        path.write_text(text)
        line = one_line(poppy("config", "validate", str(path)), 1)
        assert "nested more than 32 levels deep" in line


def test_play_refuses_a_move_that_would_never_end(poppy: Any, tmp_path: Path) -> None:
    slow = tmp_path / "slow.json"
    slow.write_text(
        '{"framerate": 1e-300, "positions": {"0": {"m1": [0, 0]}, "1": {"m1": [1, 0]}}}'
    )
    assert "framerate must be 0.1-1000 Hz" in one_line(poppy("play", str(slow), *SIM), 1)
    far = tmp_path / "far.json"
    far.write_text('{"framerate": 50, "positions": {"0": {"m1": [1000000.0, 0]}}}')
    assert "within ±1000" in one_line(poppy("play", str(far), *SIM), 1)


def test_play_clamps_a_move_past_the_limits_and_says_so(poppy: Any, tmp_path: Path) -> None:
    path = tmp_path / "past.json"
    path.write_text(
        '{"framerate": 50, "positions": {"0": {"m1": [500.0, 0]}, "0.02": {"m1": [500.0, 0]}}}'
    )
    result = poppy("play", str(path), *SIM, "--json")
    assert result.code == 0, result.stderr
    assert "warning: m1: the move goes" in result.stderr and "played at the limit" in result.stderr
    assert result.json()["completed"] is True
