"""`poppy serve` as the boot service runs it (issue 26.1): the page on two ports of one server,
served while the robot's port is missing, which says so and picks the motors up when they come."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from poppy_core.emulator import serve_pty
from poppy_core.robot import load_profile
from poppy_core.robot.factory import virtual_buses
from tests.helpers.cli import command_env
from tests.helpers.processes import reap, served_urls
from tests.helpers.waiting import eventually, http_timeout, scaled

POPPY = [sys.executable, "-m", "poppy_cli"]


def start_serving(*args: str) -> tuple[subprocess.Popen[str], list[str]]:
    """``poppy serve ARGS`` in a process, and the http:// URLs it printed."""
    env = dict(os.environ, **command_env())
    proc = subprocess.Popen(
        [*POPPY, "serve", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    assert proc.stdout is not None
    return proc, served_urls(proc.stdout)


def stop(proc: subprocess.Popen[str]) -> str:
    """SIGTERM, the exit code checked; what it said on stderr."""
    try:
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=scaled(30)) == 0
        assert proc.stderr is not None
        return proc.stderr.read()
    finally:
        reap(proc)


@pytest.fixture
def missing_port(tmp_path: Path) -> str:
    return str(tmp_path / "ttyDXL")


@pytest.fixture
def served_waiting(missing_port: str) -> Iterator[tuple[subprocess.Popen[str], list[str]]]:
    proc, urls = start_serving(
        "--http",
        "--http-port",
        "0",
        "--http-port",
        "0",
        "--profile",
        "ergo-jr",
        "--port",
        missing_port,
        "--wait-for-motors",
        "--no-sensors",
    )
    try:
        yield proc, urls
    finally:
        reap(proc)


def test_a_missing_port_is_served_anyway_then_its_motors_are_picked_up(
    served_waiting: tuple[subprocess.Popen[str], list[str]], missing_port: str
) -> None:
    proc, urls = served_waiting
    assert len(urls) == 2 and urls[0] != urls[1], urls
    for url in urls:  # the page on both ports, from one server
        page = httpx.get(url + "/", timeout=http_timeout(30))
        assert page.status_code == 200 and "Release the motors" in page.text
    access = httpx.get(urls[1] + "/api/v1/motors/access", timeout=http_timeout(30)).json()
    message = f"no motors on {missing_port} — is the power on?"
    assert access["no_motors"] == [{"port": missing_port, "message": message}]
    motors = httpx.get(urls[0] + "/api/v1/motors", timeout=http_timeout(30)).json()
    assert [m["online"] for m in motors] == [False] * 6

    (virtual,) = virtual_buses(load_profile("ergo-jr")).values()
    with serve_pty(virtual, link=missing_port):  # the power comes on

        def all_online() -> bool:
            found = httpx.get(urls[0] + "/api/v1/motors", timeout=http_timeout(30)).json()
            return all(m["online"] for m in found)

        assert eventually(all_online, timeout_s=30)

        def no_missing_port() -> bool:  # the access report follows the motors' health
            access = httpx.get(urls[0] + "/api/v1/motors/access", timeout=http_timeout(30)).json()
            return access["no_motors"] == []

        assert eventually(no_missing_port, timeout_s=30)
        said = stop(proc)
    assert message in said  # the log (the journal of the service) says it once too


def test_one_page_of_each_port_may_use_the_other(
    served_waiting: tuple[subprocess.Popen[str], list[str]],
) -> None:
    proc, urls = served_waiting
    port = urls[0].rsplit(":", 1)[1]
    # a page of port A calling port B: the server's own, so no refusal
    answer = httpx.post(
        urls[1] + "/api/v1/motors/release",
        headers={"Origin": f"http://127.0.0.1:{port}"},
        timeout=http_timeout(),
    )
    assert answer.status_code == 200, answer.text
    foreign = httpx.post(
        urls[1] + "/api/v1/motors/take",
        headers={"Origin": "http://evil.test"},
        timeout=http_timeout(),
    )
    assert foreign.status_code == 403
    stop(proc)


def test_the_same_http_port_twice_is_a_usage_error() -> None:
    twice = ["--http-port", "8123", "--http-port", "8123"]
    done = subprocess.run(
        [*POPPY, "serve", "--http", "--sim", "--profile", "ergo-jr", *twice],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert "--http-port: the HTTP port 8123 is given twice" in done.stderr
    assert "Traceback" not in done.stderr
