"""The robot's page names its robot and uses the width, in Debian's chromium (Playwright).

A robot served ``--name jr1`` is "jr1" in its header, its tab and ``/api/v1/web/about``; a token
is asked for without an outage banner; the 3D view sits beside the motor table on a desktop and
under it on a phone; behaviours are one compact row each; settings are one click away;
the camera panel is labelled; Snap! and Jupyter are linked only when served; the speed column
moves while a goto plays.
"""

from __future__ import annotations

import http.server
import json
import threading
from collections.abc import Iterator
from typing import Any

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, serve
from tests.helpers.chromium import launched, needs_chromium
from tests.helpers.server import Served
from tests.helpers.server import serve as serve_ergo
from tests.helpers.waiting import eventually, http_timeout

pytestmark = needs_chromium

WAIT_MS = 60_000
LIVE = "() => window.poppy && window.poppy.ready && window.poppy.stats.frames > 0"
DESKTOP = {"width": 1280, "height": 900}
PHONE = {"width": 390, "height": 844}


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    yield from launched()


@pytest.fixture(scope="module")
def jr1(moves_folder: str) -> Iterator[Any]:
    """A virtual Ergo Jr served as ``poppy serve --http --snap --name jr1`` serves it."""
    robot = from_profile("ergo-jr", sim=True)
    try:
        with serve(robot, ServeSpec(http=Listen(), snap=Listen(), name="jr1")) as servers:
            servers.app.state.web_notebook_port = closed_port()  # no Jupyter there
            yield servers
    finally:
        robot.close()


@pytest.fixture(scope="module")
def served(moves_folder: str) -> Iterator[Served]:
    """A virtual Ergo Jr served without a name, a token or Snap!."""
    for served in serve_ergo(moves_folder):
        served.app.state.web_notebook_port = closed_port()
        yield served


def closed_port() -> int:
    """A loopback port nothing listens on (bound, then closed)."""
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture(scope="module")
def tab(browser: Any) -> Iterator[Any]:
    """The module's tab, where each test loads its page afresh at its size (a new context costs
    the browser about three times as much; no test keeps a token in this one)."""
    context = browser.new_context(viewport=DESKTOP)
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    yield page
    context.close()


def open_page(tab: Any, url: str, viewport: dict[str, int] = DESKTOP) -> Any:
    """``url``'s home page loaded afresh in the module's ``tab`` (a new document), live."""
    tab.set_viewport_size(viewport)
    tab.goto(url + "/")
    tab.wait_for_function(LIVE)
    return tab


def leave(page: Any) -> None:
    """Ends the page's stream and polls with the test (the tab stays for the next)."""
    page.goto("about:blank")


def open_phone(browser: Any, url: str) -> Any:
    """``url``'s home page in a context of its own, as a phone shows it (touch, mobile viewport)."""
    context = browser.new_context(viewport=PHONE, is_mobile=True)
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    page.goto(url + "/")
    page.wait_for_function(LIVE)
    return page


def box(page: Any, selector: str) -> dict[str, float]:
    found = page.locator(selector).bounding_box()
    assert found, f"{selector} is not shown"
    return dict(found)


def test_the_name_is_in_the_header_the_tab_and_about(tab: Any, jr1: Any) -> None:
    about = httpx.get(jr1.http.url + "/api/v1/web/about", timeout=http_timeout()).json()
    assert (about["name"], about["creature"]) == ("jr1", "ergo-jr")
    page = open_page(tab, jr1.http.url)
    try:
        assert page.inner_text("#robot-name") == "jr1"
        assert page.inner_text("#creature") == "ergo-jr"
        assert page.title() == "jr1 · ergo-jr"
    finally:
        leave(page)


def test_a_robot_without_a_name_is_named_once(tab: Any, served: Served) -> None:
    # it said "ergo-jr ergo-jr" (the profile as the name, and again as the creature)
    page = open_page(tab, served.url)
    try:
        assert page.inner_text("#robot-name") == "ergo-jr"
        assert page.inner_text("#creature") == ""
        assert page.title() == "ergo-jr · poppy"
    finally:
        leave(page)


def test_with_snap_the_header_is_one_line_and_links_snap_not_a_dead_jupyter(
    tab: Any, jr1: Any
) -> None:
    page = open_page(tab, jr1.http.url)
    try:
        links = page.eval_on_selector_all("#links a", "as => as.map(a => a.textContent)")
        assert links == ["Snap! with the Poppy blocks"], links  # no Jupyter answers
        parts = ["#robot-name", "#sim-badge", "#conn", "#links a", "#settings-open", "#stop-all"]
        parts.append("#release-motors")
        middles = {p: box(page, p)["y"] + box(page, p)["height"] / 2 for p in parts}
        assert max(middles.values()) - min(middles.values()) < 12, f"the header wraps: {middles}"
        assert box(page, "header")["height"] < 80
    finally:
        leave(page)


def test_a_robot_without_snap_links_no_snap(tab: Any, served: Served) -> None:
    page = open_page(tab, served.url)
    try:
        assert page.locator("#links a").count() == 0
        assert "API docs" in page.inner_text("#dev-links")  # the programmers' links stay
    finally:
        leave(page)


class FakeJupyter(http.server.BaseHTTPRequestHandler):
    """Answers ``GET /api`` as jupyter_server does (its version, no login needed)."""

    def do_GET(self) -> None:
        body = json.dumps({"version": "2.14.2"}).encode() if self.path == "/api" else b"{}"
        self.send_response(200 if self.path == "/api" else 404)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: Any) -> None:
        pass


class NotJupyter(FakeJupyter):
    """Something else on the notebook's port: no ``/api`` version."""

    def do_GET(self) -> None:
        self.send_response(404)
        self.send_header("Content-Length", "0")
        self.end_headers()


def listening(handler: type) -> http.server.ThreadingHTTPServer:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def jupyter_link(page: Any) -> str | None:
    found = page.query_selector("#link-jupyter")
    return found.get_attribute("href") if found else None


def test_the_jupyter_link_shows_only_while_a_jupyter_answers(tab: Any, served: Served) -> None:
    state = served.app.state
    other = listening(NotJupyter)
    jupyter = listening(FakeJupyter)
    try:
        state.web_notebook_port = other.server_address[1]
        about = served.url + "/api/v1/web/about"
        assert httpx.get(about, timeout=http_timeout()).json()["notebook"] is None
        port = jupyter.server_address[1]
        state.web_notebook_port = port
        assert httpx.get(about, timeout=http_timeout()).json()["notebook"] == {
            "port": port,
            "path": "/notebooks/discover-your-robot.ipynb",
        }
        page = open_page(tab, served.url)
        try:
            want = f"http://127.0.0.1:{port}/notebooks/discover-your-robot.ipynb"
            assert jupyter_link(page) == want
            assert page.inner_text("#link-jupyter") == "Jupyter: discover your robot"
            jupyter.shutdown()
            jupyter.server_close()
            # the page reads about every 5 s; the server asks Jupyter again after 3 s
            assert eventually(lambda: jupyter_link(page) is None, 30.0), "a dead Jupyter linked"
        finally:
            leave(page)
    finally:
        other.shutdown()
        other.server_close()
        state.web_notebook_port = closed_port()


@pytest.fixture(scope="module")
def with_token(moves_folder: str) -> Iterator[Served]:
    yield from serve_ergo(moves_folder, token="s3cret-layout")


# Records, from the page's first script on, whether the outage banner ever showed.
BANNER_WATCH = """
window.__bannerShown = false;
new MutationObserver(() => {
  const banner = document.getElementById("offline");
  if (banner && !banner.hidden) window.__bannerShown = true;
}).observe(document, { subtree: true, attributes: true, childList: true });
"""


def test_the_token_prompt_is_no_outage(browser: Any, with_token: Served) -> None:
    context = browser.new_context(viewport=DESKTOP)
    context.add_init_script(BANNER_WATCH)
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    try:
        page.goto(with_token.url + "/")
        page.wait_for_selector("#token-dialog[open]")
        page.wait_for_timeout(1500)  # the refused stream has closed meanwhile and retried
        assert page.is_hidden("#offline")
        assert page.inner_text("#conn") == "token needed"
        assert not page.evaluate("window.__bannerShown"), "the outage banner showed"
        page.fill("#token-input", "s3cret-layout")
        page.click("#token-ok")
        page.wait_for_function(LIVE)
        assert page.inner_text("#conn") == "connected"
        assert not page.evaluate("window.__bannerShown")
    finally:
        context.close()


def test_desktop_the_3d_view_sits_beside_the_table(tab: Any, served: Served) -> None:
    page = open_page(tab, served.url)
    try:
        view, motors = box(page, "#view3d"), box(page, "#motors")
        assert view["x"] + view["width"] <= motors["x"], (view, motors)
        assert (
            view["y"] < motors["y"] + motors["height"] and motors["y"] < view["y"] + view["height"]
        )
        assert motors["width"] > 1.8 * view["width"]  # the table gets the room
        used = max(box(page, s)["x"] + box(page, s)["width"] for s in ("#motors", "#primitives"))
        assert used > 1200, f"the page leaves {1280 - used:.0f} px empty on the right"
    finally:
        leave(page)


def test_phone_the_view_is_under_the_table_and_nothing_is_wider(
    browser: Any, served: Served
) -> None:
    page = open_phone(browser, served.url)
    try:
        assert page.evaluate("document.documentElement.scrollWidth") <= PHONE["width"]
        view, motors = box(page, "#view3d"), box(page, "#motors")
        assert view["y"] >= motors["y"] + motors["height"], (view, motors)
        assert abs(view["x"] - motors["x"]) < 2 and abs(view["width"] - motors["width"]) < 2
        assert page.is_visible("#stop-all") and page.is_visible("#settings-open")
    finally:
        page.context.close()


ROWS = """rows => rows.map(row => ({
  name: row.dataset.primitive,
  height: row.querySelector('.row').getBoundingClientRect().height,
  buttons: [...row.querySelectorAll('button')].filter(b => b.offsetParent !== null)
    .map(b => [b.textContent, b.getBoundingClientRect().height]),
}))"""


@pytest.mark.parametrize("viewport", [DESKTOP, PHONE], ids=["desktop", "phone"])
def test_behaviours_are_one_compact_row_each_with_one_toggle(
    tab: Any, served: Served, viewport: dict[str, int]
) -> None:
    page = open_page(tab, served.url, viewport)
    try:
        page.wait_for_selector("#primitive-sinus")
        rows = page.eval_on_selector_all("#primitive-list > li", ROWS)
        assert len(rows) == len(served.robot.primitives) > 10
        for row in rows:
            texts = [text for text, _ in row["buttons"]]
            assert texts == ["start", "⋯"], row  # one toggle (and the fold)
            assert all(height < 40 for _, height in row["buttons"]), row  # no label wraps
            assert row["height"] < 44, row
        if viewport is DESKTOP:  # two rows side by side: the list is half as tall
            tops = page.eval_on_selector_all(
                "#primitive-list > li",
                "ls => ls.map(l => Math.round(l.getBoundingClientRect().top))",
            )
            assert len(set(tops)) <= (len(tops) + 1) // 2
    finally:
        leave(page)


TABLET = {"width": 820, "height": 1180}
TOP = "sel => document.querySelector(sel).getBoundingClientRect().top + window.scrollY"
FILLED = (
    "() => window.poppy.view && window.poppy.view.frames > 0"
    " && window.poppy.datasets && window.poppy.datasets.ready"
)


@pytest.mark.parametrize("viewport", [DESKTOP, TABLET, PHONE], ids=["desktop", "tablet", "phone"])
def test_the_behaviours_stay_where_they_were_when_the_page_went_live(
    tab: Any, served: Served, viewport: dict[str, int]
) -> None:
    """What fills in after the page is live (the 3D view once drawn, the datasets once read)
    keeps its room or sits under the behaviours: a row a student aims at is still there when
    the click lands (on one column the view grew by 240-480 px above them, a loaded run's
    lost click)."""
    page = open_page(tab, served.url, viewport)
    try:
        live = page.evaluate(TOP, "#primitives")
        page.locator("#view3d").scroll_into_view_if_needed()  # the view loads once shown
        page.wait_for_function(FILLED)
        page.wait_for_selector("#primitive-sinus")
        moved = page.evaluate(TOP, "#primitives") - live
        assert abs(moved) < 1, f"the behaviours moved by {moved} px"  # < 1: the canvas's rounding
        if viewport is not DESKTOP:  # one column: the datasets under the lists they would push
            assert page.evaluate(TOP, "#datasets") > page.evaluate(TOP, "#moves")
    finally:
        leave(page)


def test_the_toggle_starts_and_stops_and_the_fold_pauses(tab: Any, served: Served) -> None:
    page = open_page(tab, served.url)
    robot = served.robot
    toggle = "#primitive-square button.run"

    def shown() -> tuple[Any, ...]:
        return (
            page.get_attribute(toggle, "aria-label"),
            page.get_attribute(toggle, "aria-pressed"),
            page.is_enabled("button[aria-label='pause square']"),
            page.is_enabled("button[aria-label='resume square']"),
        )

    try:
        assert eventually(lambda: shown() == ("start square", "false", False, False))
        page.click(toggle)
        assert eventually(lambda: shown() == ("stop square", "true", True, False)), shown()
        assert robot.square.is_alive()
        page.click("button[aria-label^='more of square']")
        page.click("button[aria-label='pause square']")
        assert eventually(lambda: shown() == ("stop square", "true", False, True)), shown()
        page.click("button[aria-label='resume square']")
        assert eventually(lambda: shown() == ("stop square", "true", True, False)), shown()
        page.click(toggle)
        assert eventually(lambda: not robot.square.is_alive())
        assert eventually(lambda: shown() == ("start square", "false", False, False)), shown()
    finally:
        leave(page)
        robot.compliant = True


@pytest.mark.parametrize("viewport", [DESKTOP, PHONE], ids=["desktop", "phone"])
def test_settings_are_one_click_from_the_header(
    tab: Any, served: Served, viewport: dict[str, int]
) -> None:
    page = open_page(tab, served.url, viewport)
    try:
        page.evaluate("window.scrollTo(0, document.body.scrollHeight)")  # wherever one is
        page.click("#settings-open")
        page.wait_for_selector("#settings-version")
        settings = box(page, "#settings")
        assert 0 <= settings["y"] < viewport["height"], settings  # on screen, at the top
        assert page.get_attribute("#settings-open", "aria-expanded") == "true"
        page.click("#settings-open")
        assert page.is_hidden("#settings")
    finally:
        leave(page)


def test_an_ideal_sim_camera_panel_says_no_camera(tab: Any, served: Served) -> None:
    about = httpx.get(served.url + "/api/v1/web/about", timeout=http_timeout()).json()
    assert about["camera_views"] == [] and about["cameras"] == ["camera"]  # a DummyCamera
    page = open_page(tab, served.url)
    try:
        assert page.inner_text("#camera-h") == "Camera"
        assert page.inner_text("#no-camera").startswith("No camera")
        assert "--sim mujoco" in page.inner_text("#no-camera")
        assert page.query_selector("#camera-views img") is None  # no black square
    finally:
        leave(page)


MEAN_PIXEL = """img => {
  const canvas = document.createElement("canvas");
  canvas.width = img.naturalWidth; canvas.height = img.naturalHeight;
  const context = canvas.getContext("2d");
  context.drawImage(img, 0, 0);
  const data = context.getImageData(0, 0, canvas.width, canvas.height).data;
  let sum = 0;
  for (let i = 0; i < data.length; i += 4) sum += data[i] + data[i + 1] + data[i + 2];
  return sum / (data.length / 4) / 3;
}"""


@pytest.fixture(scope="module")
def mujoco_robot(moves_folder: str) -> Iterator[Served]:
    pytest.importorskip("mujoco")
    from poppy_core.errors import SensorError
    from tests.helpers.server import serve_robot

    robot = from_profile("ergo-jr", sim="mujoco")
    try:
        robot.camera.latest(timeout_s=30)
    except SensorError as exc:
        robot.close()
        pytest.skip(f"no OpenGL for offscreen rendering here ({exc}); `make sim-deps`")
    yield from serve_robot(robot)


def test_under_mujoco_the_camera_panel_shows_the_simulated_picture(
    tab: Any, mujoco_robot: Served
) -> None:
    page = open_page(tab, mujoco_robot.url)
    try:
        label = page.inner_text("#camera-camera .camera-label")
        assert label.startswith("camera: simulated by MuJoCo"), label
        page.click("#camera-camera button")
        img = page.locator("#camera-camera img")
        assert eventually(lambda: img.evaluate("i => i.naturalWidth") > 0, 30.0)
        assert eventually(lambda: img.evaluate(MEAN_PIXEL) > 20, 30.0), "a black picture"
    finally:
        leave(page)


def test_the_speed_column_moves_while_a_goto_plays(tab: Any, served: Served) -> None:
    # it read 0.0 while the arm danced: the emulator's present speed was 0 during a goto
    page = open_page(tab, served.url)
    robot = served.robot
    speeds: list[float] = []

    def speed() -> float:
        return float(page.inner_text("#motor-m1 td:nth-of-type(3)"))

    def at_goto_speed() -> bool:  # 60° in 3 s: 20 °/s on average, about 40 at the middle
        speeds.append(speed())
        return 10 < speeds[-1] < 100

    try:
        robot.compliant = False
        robot.goto_position({"m1": 0.0}, 0.5, wait=True)
        assert eventually(lambda: speed() == 0.0), "m1 still at 0°"
        robot.goto_position({"m1": 60.0}, 3.0, wait=False)
        assert eventually(at_goto_speed, 30.0), f"the speed column read {sorted(set(speeds))}"
    finally:
        leave(page)
        robot.goto_position({"m1": 0.0}, 0.5, wait=True)
        robot.compliant = True
