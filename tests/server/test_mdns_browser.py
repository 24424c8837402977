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

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.remote.discovery import resolve
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


@pytest.fixture(scope="module")
def tab(browser: Any) -> Iterator[Any]:
    """The module's tab, where each test opens its page afresh (a new context costs the browser
    about three times what loading a page in this one does)."""
    context = browser.new_context()
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    yield page
    context.close()


def _open(tab: Any, url: str) -> Any:
    tab.goto(url)
    return tab


def test_the_page_is_reached_by_the_announced_name(
    tab: Any, announced: tuple[str, ServerSet]
) -> None:
    name, servers = announced
    assert servers.http is not None
    page = _open(tab, f"http://{name}.local:{servers.http.port}/")
    try:
        page.wait_for_function("() => window.poppy && window.poppy.ready")
        assert page.inner_text("#robot-name") == name  # the robot's name, its creature beside
        assert page.inner_text("#creature") == "ergo-jr"
        assert page.evaluate("() => location.host") == f"{name}.local:{servers.http.port}"
    finally:
        page.goto("about:blank")  # the page ends with the test


@pytest.mark.parametrize(
    ("site", "expected", "moved"),
    [
        ("NAME.local", {"read": 200, "put": 200, "ws": "message"}, True),
        ("evil.test", {"read": "blocked", "put": "blocked", "ws": "error"}, False),
    ],
    ids=["a page of the robot's name on another port drives it", "another site is refused"],
)
def test_a_page_on_another_port_drives_the_robot_only_from_its_name(
    tab: Any,
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
    page = _open(tab, f"http://{site.replace('NAME', name)}:{monitor.port}/")
    try:
        seen = page.wait_for_function("() => window.result").json_value()
    finally:
        page.goto("about:blank")  # the page ends with the test
    assert seen == expected
    assert robot.compliant is not moved
    robot.compliant = True


# The requests of poppy-monitor (github poppy-project/poppy-monitor a90d302: lib/ajax.js posts
# JSON with "Content-Type: application/json; charset=UTF-8", js/poppy-object.js polls
# /robot.json and uses pypot's singular /motor/ and /primitive/ paths) and of puppet-master's
# move recorder (poppy-project/puppet-master, templates/EN/move-recorder.html: jQuery's $.post
# of a JSON string, sent form-encoded, and $.get), replayed from a page of the robot's name on
# another port with each client's own request form: the paths, methods, bodies and headers as
# those clients send them (their code is not copied).
CLIENTS = """<!doctype html><title>clients</title><script>
const base = "http://%(host)s:%(port)d";
const JSON_TYPE = "application/json; charset=UTF-8";
const FORM_TYPE = "application/x-www-form-urlencoded; charset=UTF-8";
function xhr(method, path, body, type) {
  return new Promise(resolve => {
    const req = new XMLHttpRequest();
    req.open(method, base + path, true);
    req.onreadystatechange = () => { if (req.readyState == 4) resolve(req.status || "blocked"); };
    if (type) req.setRequestHeader("Content-Type", type);
    req.send(body);
  });
}
const pause = ms => new Promise(resolve => setTimeout(resolve, ms));
async function main() {
  const out = [];
  const step = async (name, run) => out.push([name, await run()]);
  // poppy-monitor
  await step("monitor robot.json", () => xhr("GET", "/robot.json", null));
  await step("monitor compliant", () => xhr("POST",
    "/motor/m1/register/compliant/value.json", JSON.stringify(false), JSON_TYPE));
  await step("monitor goal", () => xhr("POST",
    "/motor/m1/register/goal_position/value.json", JSON.stringify(10), JSON_TYPE));
  await step("monitor start", () => xhr("POST",
    "/primitive/%(primitive)s/method/start/args.json", JSON.stringify({}), JSON_TYPE));
  await step("monitor stop", () => xhr("POST",
    "/primitive/%(primitive)s/method/stop/args.json", JSON.stringify({}), JSON_TYPE));
  // puppet-master's move recorder
  await step("recorder aliases", () => xhr("GET", "/motors/aliases/list.json", null));
  await step("recorder alias", () => xhr("GET", "/motors/base/list.json", null));
  await step("recorder compliant", () => xhr("POST",
    "/motors/m2/registers/compliant/value.json", JSON.stringify(true), FORM_TYPE));
  await step("recorder record", () => xhr("POST", "/records/%(move)s/record.json",
    '{"motors": "m2,m3"}', FORM_TYPE));
  await pause(300);
  await step("recorder save", () => xhr("POST", "/records/%(move)s/save.json", '{}', FORM_TYPE));
  await step("recorder list", () => xhr("GET", "/records/list.json", null));
  await step("recorder play", () => xhr("POST", "/records/%(move)s/play.json",
    '{"speed": "1"}', FORM_TYPE));
  await step("recorder stop", () => xhr("POST", "/records/%(move)s/stop.json", '{}', FORM_TYPE));
  await step("recorder running", () => xhr("GET", "/primitives/running/list.json", null));
  window.result = out;
}
main();
</script>"""


@pytest.mark.parametrize(
    ("site", "answered"),
    [("NAME.local", "answered"), ("evil.test", "blocked")],
    ids=["from the robot's name", "from another site"],
)
def test_poppy_monitor_and_puppet_master_requests_work_from_the_robots_name_only(
    tab: Any,
    announced: tuple[str, ServerSet],
    monitor: MonitorPages,
    site: str,
    answered: Any,
) -> None:
    name, servers = announced
    assert servers.http is not None
    robot = servers.service.robot
    robot.compliant = True
    move = f"replayed-{uuid.uuid4().hex[:6]}"
    monitor.page = (
        CLIENTS
        % {
            "host": f"{name}.local",
            "port": servers.http.port,
            "primitive": "dance",
            "move": move,
        }
    ).encode()
    page = _open(tab, f"http://{site.replace('NAME', name)}:{monitor.port}/")
    try:
        seen = page.wait_for_function("() => window.result").json_value()
    finally:
        page.goto("about:blank")  # the page ends with the test
    statuses = {step: status for step, status in seen}
    if answered == "blocked":
        # a simple GET may reach the server but the page never reads it; nothing moves
        assert all(status == "blocked" for status in statuses.values()), statuses
        assert robot.m1.compliant and robot.m2.compliant
    else:
        # pypot 5 answers its writes 202 and its reads 200 (pypot/server/httpserver.py): so do we
        assert all(status in (200, 202) for status in statuses.values()), statuses
        assert statuses["monitor robot.json"] == statuses["recorder list"] == 200
        assert not robot.m1.compliant
    robot.compliant = True
