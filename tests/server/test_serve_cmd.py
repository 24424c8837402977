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

POPPY = [sys.executable, "-m", "poppy_cli"]


def _start(*args: str) -> subprocess.Popen[str]:
    env = dict(os.environ, COLUMNS="200", NO_COLOR="1")
    return subprocess.Popen(
        [*POPPY, "serve", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


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
        code = proc.wait(timeout=15)
        assert time.monotonic() - t0 < 15
        assert code == 0
        assert proc.stderr is not None and "stopped" in proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for stream in (proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()


def test_public_host_without_token_warns() -> None:
    # An unknown profile stops the command after the warning, before anything is bound.
    proc = _start("--http", "--host", "0.0.0.0", "--profile", "no-such-robot", "--sim")
    _, err = proc.communicate(timeout=30)
    assert proc.returncode != 0
    assert "without --token" in err and "anyone" in err


def test_nothing_to_serve_is_a_usage_error() -> None:
    proc = _start("--sim", "--profile", "ergo-jr")
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 2 and "--http" in err


def _poppy(*args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, COLUMNS="200", NO_COLOR="1")
    return subprocess.run(
        [*POPPY, *args], capture_output=True, text=True, timeout=60, env=env, check=False
    )


def test_robot_commands_with_remote(served: Any) -> None:
    status = _poppy("robot", "status", "--remote", served.url, "--json")
    assert status.returncode == 0, status.stderr
    state = json.loads(status.stdout)["motors"]
    assert list(state) == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert state["m1"]["model"] == "XL-320" and state["m1"]["online"] is True

    stiff = _poppy("robot", "compliant", "off", "base", "--remote", served.url, "--json")
    assert stiff.returncode == 0, stiff.stderr
    assert json.loads(stiff.stdout) == {"m1": False, "m2": False, "m3": False}
    assert served.robot.m1.compliant is False

    moved = _poppy(
        "robot", "goto", "m1=12", "-d", "0.3", "--wait", "--remote", served.url, "--json"
    )
    assert moved.returncode == 0, moved.stderr
    assert json.loads(moved.stdout)["positions"]["m1"] == pytest.approx(12, abs=2)

    bad = _poppy("robot", "goto", "m9=12", "--remote", served.url)
    assert bad.returncode == 1 and "m9" in bad.stderr
    _poppy("robot", "compliant", "on", "--remote", served.url)
    assert served.robot.compliant is True


def test_primitive_and_play_with_remote(served: Any) -> None:
    from poppy_core.motion import Move, save_move

    listed = _poppy("primitive", "list", "--remote", served.url, "--json")
    assert listed.returncode == 0, listed.stderr
    assert "sinus" in json.loads(listed.stdout)

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
