"""A real browser (headless Chromium) against the Origin rules: what a page can and cannot do.

A page served on another port of 127.0.0.1 tries what an attacker's page would: a simple
cross-site POST (``no-cors``, text/plain), a CORS read, a JSON PUT (preflighted), a WebSocket and
an ``<img>`` pointing at pypot's GET that starts a primitive. Loaded from an origin the server
does not allow, nothing gets through; loaded from the allowed one (``--cors``), everything but
the image does. The page reports what it saw to the server that served it.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import httpx
import pytest

from poppy_core.server import OriginPolicy
from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="needs Debian's chromium")

PAGE = """<!doctype html><title>attack</title><script>
const base = "http://127.0.0.1:%(robot)d";
async function attempt(run) { try { return await run(); } catch (e) { return "blocked"; } }
async function main() {
  const out = {};
  out.simple = await attempt(async () => {
    await fetch(base + "/motors/%(m)s/registers/led/value.json",
      {method: "POST", mode: "no-cors", body: '"red"', headers: {"Content-Type": "text/plain"}});
    return "sent";
  });
  out.read = await attempt(async () => (await fetch(base + "/motors/list.json")).status);
  out.put = await attempt(async () => (await fetch(
    base + "/api/v1/motors/%(m)s/registers/compliant",
    {method: "PUT", headers: {"Content-Type": "application/json"},
     body: JSON.stringify({value: false})})).status);
  out.ws = await new Promise(resolve => {
    const ws = new WebSocket("ws://127.0.0.1:%(robot)d/api/v1/ws");
    ws.onmessage = () => { resolve("message"); ws.close(); };
    ws.onerror = () => resolve("error");
    setTimeout(() => resolve("timeout"), 10000);
  });
  out.img = await new Promise(resolve => {
    const img = new Image();
    img.onload = () => resolve("loaded"); img.onerror = () => resolve("error");
    img.src = base + "/primitives/sinus/start.json";
  });
  await fetch("/result", {method: "POST", body: JSON.stringify(out)});
}
main();
</script>"""


class PageServer:
    """Serves the attacking page on 127.0.0.1 and collects what it reports."""

    def __init__(self) -> None:
        self.results: list[dict[str, Any]] = []
        self.page = ""
        owner = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                body = owner.page.encode()
                self.send_response(200)
                self.send_header("Content-Type", "text/html")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def do_POST(self) -> None:
                length = int(self.headers["Content-Length"])
                owner.results.append(json.loads(self.rfile.read(length)))
                self.send_response(204)
                self.end_headers()

            def log_message(self, *args: Any) -> None:
                pass

        self.http = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = self.http.server_address[1]
        threading.Thread(target=self.http.serve_forever, daemon=True).start()

    def visit(self, url: str, timeout_s: float = 90.0) -> dict[str, Any]:
        """Open ``url`` in headless Chromium and return what the page reported."""
        self.results.clear()
        # Chromium's helper processes may still write the profile as it goes: a leftover file
        # there must not fail the test.
        with tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile:
            browser = subprocess.Popen(
                [
                    str(CHROMIUM),
                    "--headless",
                    "--no-sandbox",
                    "--disable-gpu",
                    "--no-first-run",
                    f"--user-data-dir={profile}",
                    url,
                ],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,  # its helper processes too are killed at the end
            )
            try:
                deadline = time.monotonic() + timeout_s
                while not self.results:
                    assert time.monotonic() < deadline, "the page did not report"
                    assert browser.poll() is None, "chromium exited"
                    time.sleep(0.1)
            finally:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(browser.pid, signal.SIGKILL)
                browser.wait()
        return self.results[0]


@pytest.fixture(scope="module")
def pages() -> Iterator[PageServer]:
    server = PageServer()
    yield server
    server.http.shutdown()


@pytest.fixture(scope="module")
def robot_for_localhost(moves_folder: str, pages: PageServer) -> Iterator[Served]:
    """A served robot allowing pages of http://localhost:<page port> only."""
    yield from serve(moves_folder, policy=OriginPolicy([f"http://localhost:{pages.port}"]))


def _prepare(pages: PageServer, served: Served, motor: str) -> None:
    robot_port = int(served.url.rsplit(":", 1)[1])
    pages.page = PAGE % {"robot": robot_port, "m": motor}
    served.robot.compliant = True
    served.robot.motor(motor).led = "off"


def test_a_page_of_a_foreign_origin_gets_nothing_through(
    pages: PageServer, robot_for_localhost: Served
) -> None:
    robot = robot_for_localhost.robot
    _prepare(pages, robot_for_localhost, "m1")
    seen = pages.visit(f"http://127.0.0.1:{pages.port}/")
    assert seen == {
        "simple": "sent",  # the browser sends it; the server refuses it
        "read": "blocked",
        "put": "blocked",
        "ws": "error",
        "img": "error",
    }
    assert robot.m1.led == "off" and robot.m1.compliant is True
    assert not robot.sinus.is_alive()


def test_a_page_of_an_allowed_origin_drives_the_robot(
    pages: PageServer, robot_for_localhost: Served
) -> None:
    robot = robot_for_localhost.robot
    _prepare(pages, robot_for_localhost, "m2")
    seen = pages.visit(f"http://localhost:{pages.port}/")
    assert seen == {"simple": "sent", "read": 200, "put": 200, "ws": "message", "img": "error"}
    assert robot.m2.led == "red" and robot.m2.compliant is False
    assert not robot.sinus.is_alive()  # an <img> sends no Origin: cross-site GETs stay refused
    robot.compliant = True
    robot.m2.led = "off"


# -- every spelling of every GET that changes the robot (issue 23, item 8) ---------------------

SPELLINGS_PAGE = """<!doctype html><title>images</title><script>
const base = "http://127.0.0.1:%(robot)d";
async function main() {
  const out = {};
  for (const path of %(paths)s) {
    out[path] = await new Promise(resolve => {
      const img = new Image();
      img.onload = () => resolve("loaded"); img.onerror = () => resolve("error");
      img.src = base + path;
    });
  }
  await fetch("/result", {method: "POST", body: JSON.stringify(out)});
}
main();
</script>"""

TARGETS = {"start": "sinus", "stop": "cosinus", "pause": "cosinus", "resume": "square"}
"""The primitive each action is tried on: sinus idle, cosinus running, square paused."""


def _spellings(app: Any) -> dict[str, list[str]]:
    """Action -> every path reaching its route, derived from the routes the guard marks."""
    from poppy_core.server.legacy_paths import current_path
    from poppy_core.server.state_routes import marked_routes

    found: dict[str, list[str]] = {}
    for template, _ in marked_routes(app):
        action = template.rsplit("/", 1)[1].split(".")[0]
        path = template.replace("{primitive}", TARGETS[action])
        legacy = path.replace("/primitives/", "/primitive/", 1)
        assert current_path(legacy) == path  # pypot's old spelling of this route
        encoded = legacy.replace("/primitive/", "/primitive%2F", 1)  # the server decodes it
        found[action] = [path, path + "/", legacy, encoded]
    return found


def test_no_spelling_of_a_state_changing_get_works_from_another_site(
    pages: PageServer, robot_for_localhost: Served
) -> None:
    robot = robot_for_localhost.robot
    spellings = _spellings(robot_for_localhost.app)
    assert set(spellings) == {"start", "stop", "pause", "resume"}
    for name in ("sinus", "cosinus", "square"):
        getattr(robot, name).stop()
    robot.cosinus.start()
    robot.square.start()
    robot.square.pause()
    try:
        robot_port = int(robot_for_localhost.url.rsplit(":", 1)[1])
        paths = [p for action in ("start", "stop", "pause", "resume") for p in spellings[action]]
        pages.page = SPELLINGS_PAGE % {"robot": robot_port, "paths": json.dumps(paths)}
        seen = pages.visit(f"http://127.0.0.1:{pages.port}/")
        assert set(seen) == set(paths)  # the page tried them all
        assert not robot.sinus.is_alive()  # not started
        assert robot.cosinus.state == "running"  # neither stopped nor paused
        assert robot.square.state == "paused"  # not resumed
    finally:
        for name in ("sinus", "cosinus", "square"):
            getattr(robot, name).stop()
    # each spelling does reach its route: a script (no Sec-Fetch-Site) drives sinus through it
    with httpx.Client(
        base_url=robot_for_localhost.url, follow_redirects=True, timeout=http_timeout()
    ) as http:
        for i in range(len(spellings["start"])):
            for action in ("start", "pause", "resume", "stop"):
                path = spellings[action][i].replace(f"/{TARGETS[action]}", "/sinus")
                answer = http.get(path)
                assert answer.status_code == 202, (path, answer.text)
