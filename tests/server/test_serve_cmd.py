"""`poppy serve`: prints its URLs, serves, and stops cleanly on SIGTERM / Ctrl-C."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import urllib.request
from typing import Any

import pytest

from tests.helpers.cli import command_env, keyed, run_poppy
from tests.helpers.processes import reap, start
from tests.helpers.waiting import scaled

POPPY = [sys.executable, "-m", "poppy_cli"]


def _start(*args: str) -> subprocess.Popen[str]:
    env = dict(os.environ, **command_env())
    return start([*POPPY, "serve", *args], env)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_serve_prints_urls_and_stops(signum: int) -> None:
    proc = _start(
        "--http", "--sim", "--profile", "ergo-jr", "--http-port", "0", "--ws", "--ws-port", "0"
    )
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().strip()
        ws_url = proc.stdout.readline().strip()
        assert url.startswith("http://127.0.0.1:")
        assert ws_url.startswith("ws://127.0.0.1:")
        with urllib.request.urlopen(f"{url}/motors/list.json", timeout=5) as answer:
            assert json.load(answer)["motors"][0] == "m1"
        from websockets.sync.client import connect

        with connect(ws_url) as ws:
            assert "present_position" in ws.recv(timeout=2)
        t0 = time.monotonic()
        proc.send_signal(signum)
        code = proc.wait(timeout=scaled(15))
        assert time.monotonic() - t0 < 15
        assert code == 0
        assert proc.stderr is not None and "stopped" in proc.stderr.read()
    finally:
        reap(proc)


def test_public_host_without_token_warns() -> None:
    # An unknown profile stops the command after the warning, before anything is bound.
    proc = _poppy("serve", "--http", "--host", "0.0.0.0", "--profile", "no-such-robot", "--sim")
    err = proc.stderr
    assert proc.returncode != 0
    assert "without a token" in err and "anyone" in err


def test_open_cors_warns() -> None:
    proc = _poppy("serve", "--http", "--cors", "*", "--profile", "no-such-robot", "--sim")
    err = proc.stderr
    assert proc.returncode != 0
    assert "cors '*': every web page you open can move the robot" in err


def test_nothing_to_serve_is_a_usage_error() -> None:
    proc = _poppy("serve", "--sim", "--profile", "ergo-jr")
    err = proc.stderr
    assert proc.returncode == 2 and "--http" in err


def _poppy(*args: str) -> subprocess.CompletedProcess[str]:
    """`poppy ARGS` run in this process (as a fresh one would), for commands that end."""
    result = run_poppy(*args)
    return subprocess.CompletedProcess(args, result.code, result.stdout, result.stderr)


def test_robot_commands_with_remote(served: Any) -> None:
    status = _poppy("robot", "status", "--remote", served.url, "--json")
    assert status.returncode == 0, status.stderr
    state = keyed(json.loads(status.stdout)["motors"])
    assert list(state) == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert state["m1"]["model"] == "XL-320" and state["m1"]["online"] is True

    stiff = _poppy("robot", "compliant", "off", "base", "--remote", served.url, "--json")
    assert stiff.returncode == 0, stiff.stderr
    assert json.loads(stiff.stdout) == [{"name": f"m{i}", "compliant": False} for i in (1, 2, 3)]
    assert served.robot.m1.compliant is False

    moved = _poppy(
        "robot", "goto", "m1=12", "-d", "0.3", "--wait", "--remote", served.url, "--json"
    )
    assert moved.returncode == 0, moved.stderr
    [m1] = json.loads(moved.stdout)["motors"]
    assert m1["name"] == "m1" and m1["position"] == pytest.approx(12, abs=2)

    bad = _poppy("robot", "goto", "m9=12", "--remote", served.url)
    assert bad.returncode == 1 and "m9" in bad.stderr
    _poppy("robot", "compliant", "on", "--remote", served.url)
    assert served.robot.compliant is True


def test_primitive_and_play_with_remote(served: Any) -> None:
    from poppy_core.motion import Move, save_move

    listed = _poppy("primitive", "list", "--remote", served.url, "--json")
    assert listed.returncode == 0, listed.stderr
    assert "sinus" in keyed(json.loads(listed.stdout))

    ran = _poppy(
        "primitive",
        "run",
        "sinus",
        "--duration",
        "0.5",
        "--set",
        "amplitude=10",
        "--remote",
        served.url,
        "--json",
    )
    assert ran.returncode == 0, ran.stderr
    report = json.loads(ran.stdout)
    assert report["state"] == "stopped" and report["properties"]["amplitude"] == 10
    assert served.robot.sinus.is_alive() is False

    missing = _poppy("primitive", "run", "nope", "--remote", served.url)
    assert missing.returncode == 1 and "nope" in missing.stderr

    # the server's library is POPPY_MOVES_DIR (the module's moves folder, shared by env)
    frames = [{"m1": 10.0 * i / 24} for i in range(25)]
    save_move(Move.from_frames(50.0, frames), "remote_wave")
    played = _poppy("play", "remote_wave", "--speed", "2", "--remote", served.url, "--json")
    assert played.returncode == 0, played.stderr
    summary = json.loads(played.stdout)
    assert summary["interrupted"] is False and summary["name"] == "remote_wave"
    assert served.robot.m1.goal_position == pytest.approx(10, abs=1)

    unknown = _poppy("play", "no_such_move", "--remote", served.url)
    assert unknown.returncode == 1 and "no_such_move" in unknown.stderr


def _serve_fails(*args: str) -> subprocess.CompletedProcess[str]:
    return _poppy("serve", "--sim", "--profile", "ergo-jr", *args)


def test_ws_port_equal_to_http_port_is_a_usage_error_before_any_url() -> None:
    done = _serve_fails("--http", "--ws", "--http-port", "8765", "--ws-port", "8765")
    assert done.returncode == 2 and done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "--ws-port: the WebSocket port 8765 is also the HTTP port" in lines[0]


def test_a_name_that_does_not_resolve_is_not_a_busy_port() -> None:
    done = _serve_fails(
        "--http", "--host", "no-such-host.invalid", "--http-port", "0", "--token", "t"
    )
    assert done.returncode == 1 and done.stdout == ""
    assert "does not resolve" in done.stderr and "in use" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_an_address_of_another_machine_is_named() -> None:
    done = _serve_fails("--http", "--host", "192.0.2.1", "--http-port", "0", "--token", "t")
    assert done.returncode == 1
    assert "192.0.2.1 is not an address of this machine" in done.stderr


def test_a_busy_port_is_named_and_the_ws_port_is_checked_before_serving() -> None:
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        busy = str(taken.getsockname()[1])
        done = _serve_fails("--http", "--http-port", busy)
        assert done.returncode == 1 and done.stdout == ""
        assert f"127.0.0.1:{busy}: the port is already in use" in done.stderr
        both = _serve_fails("--http", "--http-port", "0", "--ws", "--ws-port", busy)
        assert both.returncode == 1 and both.stdout == ""  # no URL printed for the HTTP server
        assert "already in use" in both.stderr


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_a_refused_permission_is_named() -> None:
    from poppy_core.server import ListenError, bind_sockets

    read, write = os.pipe()
    child = os.fork()
    if child == 0:  # pragma: no cover (runs in the child)
        message = "bound"
        try:
            if os.geteuid() == 0:
                os.setuid(65534)  # nobody: ports below 1024 are refused again
            bind_sockets("127.0.0.1", 1)
        except ListenError as exc:
            message = str(exc)
        except BaseException as exc:
            message = repr(exc)
        os.write(write, message.encode())
        os._exit(0)
    os.close(write)
    os.waitpid(child, 0)
    message = os.read(read, 4096).decode()
    os.close(read)
    if message == "bound":
        pytest.skip("this machine lets every user listen on port 1")
    assert message.startswith("cannot listen on 127.0.0.1:1: permission denied")
    assert "ports below 1024 need root" in message


@pytest.mark.parametrize(
    ("option", "value"), [("--cors", "snap.berkeley.edu"), ("--allow-host", "http://x/")]
)
def test_bad_origins_and_host_names_are_usage_errors(option: str, value: str) -> None:
    done = _serve_fails("--http", option, value)
    assert done.returncode == 2 and done.stdout == ""
    assert len(done.stderr.strip().splitlines()) == 1 and value in done.stderr


def test_both_websockets_apply_the_origin_rules_and_say_how_to_allow_one() -> None:
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    proc = _start(
        "--http",
        "--sim",
        "--profile",
        "ergo-jr",
        "--http-port",
        "0",
        "--ws",
        "--ws-port",
        "0",
        "--cors",
        "https://my.app",
    )
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().strip()
        ws_url = proc.stdout.readline().strip()
        port = url.rsplit(":", 1)[1]
        for endpoint in (ws_url, url.replace("http://", "ws://") + "/api/v1/ws"):
            for _ in range(2):
                with (
                    pytest.raises(InvalidStatus) as refused,
                    connect(
                        endpoint,
                        origin="https://evil.example",
                    ),
                ):
                    pass
                assert refused.value.response.status_code == 403
            for origin in ("https://my.app", f"http://127.0.0.1:{port}"):
                with connect(endpoint, origin=origin) as ws:
                    assert "present_position" in ws.recv(timeout=5)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=scaled(15)) == 0
        assert proc.stderr is not None
        err = proc.stderr.read()
        hints = [line for line in err.splitlines() if "evil.example" in line]
        assert hints == [
            "warning: refused a request from the web page origin 'https://evil.example': to "
            "allow it, restart poppy serve with --cors https://evil.example"
        ]
    finally:
        reap(proc)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_a_remote_play_with_exit_130(served: Any, signum: int) -> None:
    from poppy_core.motion import Move, save_move
    from tests.helpers.waiting import eventually

    frames = [{"m1": 10.0 * i / 2999} for i in range(3000)]  # a minute at 50 Hz
    save_move(Move.from_frames(50.0, frames), "remote_long")
    env = dict(os.environ, **command_env())
    proc = start([*POPPY, "play", "remote_long", "--remote", served.url, "--json"], env)
    try:
        moves = served.app.state.service.moves
        assert eventually(lambda: "remote_long" in moves.playing(), timeout_s=60), proc.stderr
        proc.send_signal(signum)
        stdout, stderr = proc.communicate(timeout=scaled(30))
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, stderr
    assert json.loads(stdout)["interrupted"] is True
    assert eventually(lambda: "remote_long" not in moves.playing(), timeout_s=10)
