"""issue 26's done-when, in Debian's chromium (Playwright): the robot announced over mDNS on
loopback is reached by its ``.local`` name as python-zeroconf resolves it (chromium's
``--host-resolver-rules`` maps the name to that address, so the Host header is ``NAME.local``);
a monitor page served from the robot's name on another port (as the Poppy Pi's pages on 2280)
drives it, and the same page from another site is refused."""

from __future__ import annotations

import os
import threading
import uuid
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import pytest

from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.remote.discovery import resolve
from poppy_core.robot import from_profile
from tests.helpers.chromium import launched, needs_chromium

pytest.importorskip("zeroconf")
pytestmark = needs_chromium

WAIT_MS = 60_000
MONITOR = """<!doctype html><title>monitor</title><script>
const base = "http://%(host)s:%(port)d";
async function attempt(run) { try { return await run(); } catch (e) { return "blocked"; } }
async function main() {
  const out = {};
  out.read = await attempt(async () => (await fetch(base + "/api/v1/robot")).status);
  out.put = await attempt(async () => (await fetch(base + "/api/v1/robot/compliant",
    {method: "PUT", headers: {"Content-Type": "application/json"},
     body: JSON.stringify({compliant: false})})).status);
  out.ws = await new Promise(resolve => {
    const ws = new WebSocket("ws://%(host)s:%(port)d/api/v1/ws");
    ws.onmessage = () => { resolve("message"); ws.close(); };
    ws.onerror = () => resolve("error");
  });
  window.result = out;
}
main();
</script>"""


class MonitorPages:
    """A page server on another port of this machine (poppy-monitor's, puppet-master's)."""

    def __init__(self) -> None:
        self.page = b""
        owner = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                self.send_response(200)
                self.send_header("Content-Type", "text/html")
                self.send_header("Content-Length", str(len(owner.page)))
                self.end_headers()
                self.wfile.write(owner.page)

            def log_message(self, *args: Any) -> None:
                pass

        self.http = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = self.http.server_address[1]
        threading.Thread(target=self.http.serve_forever, daemon=True).start()


@pytest.fixture(scope="module")
def announced() -> Iterator[tuple[str, ServerSet]]:
    name = f"b{os.getpid()}-{uuid.uuid4().hex[:6]}"
    robot = from_profile("ergo-jr", sim=True)
    try:
        with serve(robot, ServeSpec(http=Listen(), name=name, announce=True)) as servers:
            assert servers.announcer is not None
            yield servers.announcer.name, servers
    finally:
        robot.close()


@pytest.fixture(scope="module")
def monitor() -> Iterator[MonitorPages]:
    pages = MonitorPages()
    yield pages
    pages.http.shutdown()


@pytest.fixture(scope="module")
def browser(announced: tuple[str, ServerSet]) -> Iterator[Any]:
    name, _ = announced
    addresses = resolve(f"{name}.local", 5.0, interfaces=["127.0.0.1"])  # python-zeroconf
    assert addresses == ["127.0.0.1"]
    rules = f"MAP {name}.local {addresses[0]}, MAP evil.test 127.0.0.1"
    yield from launched(f"--host-resolver-rules={rules}")


def _open(browser: Any, url: str) -> tuple[Any, Any]:
    context = browser.new_context()
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    page.goto(url)
    return context, page


def test_the_page_is_reached_by_the_announced_name(
    browser: Any, announced: tuple[str, ServerSet]
) -> None:
    name, servers = announced
    assert servers.http is not None
    context, page = _open(browser, f"http://{name}.local:{servers.http.port}/")
    try:
        page.wait_for_function("() => window.poppy && window.poppy.ready")
        assert page.inner_text("#robot-name") == "ergo-jr"
        assert page.evaluate("() => location.host") == f"{name}.local:{servers.http.port}"
    finally:
        context.close()


@pytest.mark.parametrize(
    ("site", "expected", "moved"),
    [
        ("NAME.local", {"read": 200, "put": 200, "ws": "message"}, True),
        ("evil.test", {"read": "blocked", "put": "blocked", "ws": "error"}, False),
    ],
    ids=["a page of the robot's name on another port drives it", "another site is refused"],
)
def test_a_page_on_another_port_drives_the_robot_only_from_its_name(
    browser: Any,
    announced: tuple[str, ServerSet],
    monitor: MonitorPages,
    site: str,
    expected: dict[str, Any],
    moved: bool,
) -> None:
    name, servers = announced
    assert servers.http is not None
    robot = servers.service.robot
    robot.compliant = True
    monitor.page = (MONITOR % {"host": f"{name}.local", "port": servers.http.port}).encode()
    context, page = _open(browser, f"http://{site.replace('NAME', name)}:{monitor.port}/")
    try:
        seen = page.wait_for_function("() => window.result").json_value()
    finally:
        context.close()
    assert seen == expected
    assert robot.compliant is not moved
    robot.compliant = True
