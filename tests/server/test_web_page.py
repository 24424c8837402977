"""The home page in a real browser: Debian's chromium driven by Playwright (no browser download).

Each test opens the page of a virtual Ergo Jr served on 127.0.0.1, uses it as a person would
(clicks, keys, the dialogs) and checks what the robot did, or what the page shows of the robot.
"""

from __future__ import annotations

import dataclasses
import shutil
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tests.server.conftest import Served, serve

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
playwright_api = pytest.importorskip(
    "playwright.sync_api", reason="needs playwright (pip install -e '.[test]')"
)
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="needs Debian's chromium (apt-get install chromium)"
)

WAIT_S = 30.0
# arrow functions: Playwright evaluates a bare expression string with eval, which the page's
# Content-Security-Policy refuses
READY = "() => window.poppy && window.poppy.ready"
LIVE = "() => window.poppy && window.poppy.ready && window.poppy.stats.frames > 0"


def eventually(check: Callable[[], Any], what: str, timeout_s: float = WAIT_S) -> Any:
    """Poll ``check`` until it returns something true (a load-proof wait, not a timing test)."""
    deadline = time.monotonic() + timeout_s
    while True:
        result = check()
        if result:
            return result
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with playwright_api.sync_playwright() as driver:
        launched = driver.chromium.launch(
            executable_path=CHROMIUM, args=["--no-sandbox", "--disable-gpu"]
        )
        yield launched
        launched.close()


@pytest.fixture
def page(browser: Any, served: Served) -> Iterator[Any]:
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    opened = context.new_page()
    opened.set_default_timeout(WAIT_S * 1000)
    errors: list[str] = []
    opened.on("pageerror", lambda error: errors.append(str(error)))
    opened.on(
        "console",
        lambda message: (
            errors.append(message.text) if "Content Security Policy" in message.text else None
        ),
    )
    opened.goto(served.url + "/")
    opened.wait_for_function(LIVE)
    yield opened
    context.close()
    assert not errors, errors


def cell(page: Any, motor: str, column: int) -> float:
    return float(page.inner_text(f"#motor-{motor} td:nth-of-type({column})"))


def test_the_table_shows_every_motor_and_values_move_on_a_goto(page: Any, served: Served) -> None:
    robot = served.robot
    shown = page.eval_on_selector_all(
        "#motor-table tbody tr[data-motor]", "rows => rows.map(r => r.dataset.motor)"
    )
    assert shown == [m.name for m in robot.motors]
    groups = page.eval_on_selector_all(
        "#motor-table tr.group th", "ths => ths.map(t => t.textContent)"
    )
    assert groups == ["base", "tip"]
    assert page.inner_text("#robot-name") == "ergo-jr" and page.is_visible("#sim-badge")
    robot.compliant = False
    start = cell(page, "m1", 1)
    target = 40.0 if start < 20 else 0.0
    robot.goto_position({"m1": target}, 1.0, wait=False)
    eventually(lambda: abs(cell(page, "m1", 1) - start) > 5, "m1's position to move on the page")
    eventually(lambda: abs(cell(page, "m1", 1) - target) < 2, "m1 to arrive on the page")
    robot.compliant = True


def test_compliance_toggles_change_the_robot(page: Any, served: Served) -> None:
    robot = served.robot
    robot.compliant = True
    page.uncheck("#motor-m3 input[type=checkbox]")
    eventually(lambda: robot.m3.compliant is False, "m3 stiff")
    page.click("button[aria-label='base: compliant']")
    eventually(lambda: all(m.compliant for m in robot.base), "the base group compliant")
    page.click("button[aria-label='robot: stiff']")
    eventually(lambda: not any(m.compliant for m in robot.motors), "the robot stiff")
    eventually(lambda: not page.is_checked("#motor-m6 input[type=checkbox]"), "the page to say so")
    page.click("button[aria-label='robot: compliant']")
    eventually(lambda: robot.compliant, "the robot compliant")


def test_a_goal_slider_moves_the_motor(page: Any, served: Served) -> None:
    robot = served.robot
    robot.compliant = False
    slider = page.locator("#motor-m4 input[type=range]")
    slider.focus()
    for _ in range(10):
        page.keyboard.press("ArrowRight")  # keyboard only: each press is 1 degree
    slider.dispatch_event("change")
    eventually(lambda: robot.m4.goal_position > 5, "m4's goal to follow the slider")
    robot.compliant = True


def test_a_primitive_starts_and_stops_from_its_buttons(page: Any, served: Served) -> None:
    robot = served.robot
    page.click("#primitive-sinus summary")
    page.fill("#primitive-sinus input[data-prop=amplitude]", "5")
    page.press("#primitive-sinus input[data-prop=amplitude]", "Enter")
    eventually(lambda: robot.sinus.amplitude == 5, "the amplitude set from the page")
    page.click("button[aria-label='start sinus']")
    eventually(robot.sinus.is_alive, "sinus running")
    eventually(lambda: page.get_attribute("#primitive-sinus", "data-state") == "running", "state")
    page.click("button[aria-label='stop sinus']")
    eventually(lambda: not robot.sinus.is_alive(), "sinus stopped")
    robot.compliant = True


def test_a_move_recorded_from_the_page_replays(page: Any, served: Served) -> None:
    robot = served.robot
    robot.compliant = False
    robot.goto_position({"m1": 0.0}, 0.3, wait=True)
    page.fill("#record-name", "wave")
    for motor in ("m2", "m3", "m4", "m5", "m6"):
        page.uncheck(f"#record-motors input[value={motor}]")
    page.click("#record-start")
    eventually(lambda: page.is_enabled("#record-save"), "the recording to start")
    robot.goto_position({"m1": 30.0}, 1.0, wait=True)
    page.click("#record-save")
    eventually(lambda: page.query_selector("#move-wave"), "the move in the library")
    robot.goto_position({"m1": -20.0}, 0.3, wait=True)
    page.click("button[aria-label='play wave']")
    eventually(lambda: robot.m1.present_position > 20, "m1 to replay the recorded move")
    page.click("button[aria-label='plot wave']")
    eventually(lambda: page.is_visible("#plot polyline"), "the plot")
    assert "m1" in page.inner_text("#plot-title")
    page.once("dialog", lambda dialog: dialog.accept())
    page.click("button[aria-label='delete wave']")
    eventually(lambda: page.query_selector("#move-wave") is None, "the move deleted")
    robot.compliant = True


def test_stop_stops_a_running_primitive(page: Any, served: Served) -> None:
    robot = served.robot
    robot.sinus.start()
    eventually(robot.sinus.is_alive, "sinus running")
    page.click("#stop-all")
    page.check("#stop-dialog input[value=hold]")
    page.click("#stop-confirm")
    eventually(lambda: not robot.sinus.is_alive(), "Stop to stop sinus")
    eventually(lambda: not any(m.compliant for m in robot.motors), "the motors held")
    # keyboard only: Escape opens the dialog with Stop focused, Enter confirms
    robot.cosinus.start()
    page.keyboard.press("Escape")
    eventually(lambda: page.is_visible("#stop-dialog"), "the Stop dialog")
    page.check("#stop-dialog input[value=compliant]")
    page.focus("#stop-confirm")
    page.keyboard.press("Enter")
    eventually(lambda: not robot.cosinus.is_alive(), "cosinus stopped")
    eventually(lambda: robot.compliant, "the motors compliant")
    eventually(lambda: "Stop from the web page" in page.inner_text("#log-lines"), "the log line")


def test_a_refused_goal_is_shown(page: Any, served: Served) -> None:
    motor = served.robot.m5
    old = motor.angle_limit
    motor.angle_limit = (-10.0, 10.0)  # narrowed after the page drew its slider (-90..90)
    try:
        slider = page.locator("#motor-m5 input[type=range]")
        slider.fill("60")
        slider.dispatch_event("change")
        eventually(lambda: "refused" in page.inner_text("#message"), "the refusal")
        assert "outside the angle limits" in page.inner_text("#message")
        assert "refused" in (page.get_attribute("#motor-m5", "class") or "")
        assert motor.goal_position <= 10.0
    finally:
        motor.angle_limit = old


def test_the_sensors_are_shown_and_a_lost_camera_says_why(
    page: Any, served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    eventually(lambda: "camera" in page.inner_text("#sensors"), "the sensors listed")
    assert page.get_attribute("#sensors li:first-child", "class") == "ok"
    camera = served.robot.sensor("camera")
    why = "/dev/video0 does not exist: plug the camera in"
    lost = dataclasses.replace(camera.health(), connected=False, last_error=why)
    monkeypatch.setattr(camera, "health", lambda: lost)  # as an unplugged camera's
    eventually(lambda: "lost · /dev/video0 does not exist" in page.inner_text("#sensors"),
               "the lost camera shown (the page refreshes every 5 s)")  # fmt: skip
    assert page.get_attribute("#sensors li:first-child", "class") == "bad"


def test_the_phone_layout_fits_the_screen(browser: Any, served: Served) -> None:
    context = browser.new_context(viewport={"width": 390, "height": 844}, is_mobile=True)
    phone = context.new_page()
    phone.goto(served.url + "/")
    phone.wait_for_function(READY)
    width = phone.evaluate("document.documentElement.scrollWidth")
    assert width <= 390, f"the page is {width} px wide on a 390 px phone"
    assert phone.is_visible("#stop-all")
    context.close()


@pytest.fixture(scope="module")
def with_token(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder, token="s3cret-page")


def test_with_a_token_the_page_works_after_it_is_entered(browser: Any, with_token: Served) -> None:
    context = browser.new_context()
    tab = context.new_page()
    tab.set_default_timeout(WAIT_S * 1000)
    urls: list[str] = []
    tab.on("request", lambda request: urls.append(request.url))
    tab.on("websocket", lambda socket: urls.append(socket.url))
    tab.goto(with_token.url + "/")
    tab.wait_for_selector("#token-dialog[open]")
    # nothing works without the token: no motor, no robot name
    assert tab.query_selector("#motor-table tbody tr[data-motor]") is None
    assert tab.inner_text("#robot-name") == "poppy"
    tab.fill("#token-input", "wrong")
    tab.click("#token-ok")
    tab.wait_for_selector("#token-dialog[open]")
    assert "refused" in tab.inner_text("#token-error")
    tab.fill("#token-input", "s3cret-page")
    tab.click("#token-ok")
    tab.wait_for_function(LIVE)
    assert tab.inner_text("#robot-name") == "ergo-jr"
    tab.uncheck("#motor-m2 input[type=checkbox]")
    eventually(lambda: with_token.robot.m2.compliant is False, "m2 stiff with the token")
    assert any("/api/v1/ws" in u for u in urls)
    assert not [u for u in urls if "s3cret" in u], "the token went into a URL"
    # the token is kept: a reload asks nothing
    tab.reload()
    tab.wait_for_function(READY)
    assert not tab.is_visible("#token-dialog")
    context.close()
    with_token.robot.compliant = True


@pytest.fixture(scope="module")
def creature(moves_folder: str) -> Iterator[Served]:
    """A virtual Ergo Jr as ``poppy serve`` builds it: its chain and camera attached."""
    from poppy_core.creatures import from_profile
    from poppy_core.server import ServerThread, create_app

    robot = from_profile("ergo-jr", sim=True)
    app = create_app(robot)
    server = ServerThread(app).start()
    try:
        yield Served(server.url, robot, app)
    finally:
        server.stop()
        robot.close()


def test_camera_and_chain_jog(browser: Any, creature: Served) -> None:
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    tab = context.new_page()
    tab.set_default_timeout(WAIT_S * 1000)
    tab.goto(creature.url + "/")
    tab.wait_for_function(READY)
    tab.click("#camera-views button")
    eventually(
        lambda: tab.evaluate("document.querySelector('#camera-views img').naturalWidth") > 0,
        "a camera frame in the page",
    )
    tab.click("#camera-views button")  # hidden again: the stream is closed
    robot = creature.robot
    robot.compliant = False
    chain = robot.chain
    before = chain.position.copy()
    tab.click("button[aria-label='chain z plus 10 mm']")
    eventually(lambda: chain.position[2] - before[2] > 0.005, "the tip to rise by about 1 cm")
    eventually(lambda: tab.inner_text("#chain-chain output") != "", "the tip shown")

    def shown_in_mm() -> bool:  # as the CLI and the TUI show a tip
        tip = [int(v) for v in tab.inner_text("#chain-chain output").split(", ")]
        return abs(tip[2] - chain.position[2] * 1000) < 5

    eventually(shown_in_mm, "the tip shown in millimetres")
    context.close()
    robot.compliant = True
