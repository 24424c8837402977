"""The home page in a real browser: Debian's chromium driven by Playwright (no browser download).

Each test opens the page of a virtual Ergo Jr served on 127.0.0.1, uses it as a person would
(clicks, keys, the dialogs) and checks what the robot did, or what the page shows of the robot.
"""

from __future__ import annotations

import dataclasses
import re
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from tests.helpers.chromium import launched, needs_chromium, new_tab
from tests.helpers.server import serve_robot
from tests.server.conftest import Served, serve

pytestmark = needs_chromium

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
    yield from launched()


@pytest.fixture(scope="module")
def tab(browser: Any) -> Iterator[tuple[Any, list[str]]]:
    """The module's tab and the errors its page reports (a new context costs the browser about
    three times what loading the page again in this one does)."""
    context, opened = new_tab(browser, WAIT_S * 1000)
    errors: list[str] = []
    opened.on("pageerror", lambda error: errors.append(str(error)))
    opened.on(
        "console",
        lambda message: (
            errors.append(message.text) if "Content Security Policy" in message.text else None
        ),
    )
    yield opened, errors
    context.close()


@pytest.fixture
def page(tab: tuple[Any, list[str]], served: Served) -> Iterator[Any]:
    """The home page loaded afresh in the module's tab (a new document, desktop size)."""
    opened, errors = tab
    errors.clear()
    opened.set_viewport_size({"width": 1280, "height": 900})
    opened.goto(served.url + "/")
    opened.wait_for_function(LIVE)
    yield opened
    opened.goto("about:blank")  # the page's stream and polls end with the test
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


# counts the motor table's DOM writes from now on, and the stream frames meanwhile
COUNT_WRITES = """() => {
  window.__writes = 0;
  window.__framesAtStart = window.poppy.stats.frames;
  new MutationObserver((records) => { window.__writes += records.length; }).observe(
    document.querySelector("#motor-table tbody"),
    { subtree: true, childList: true, characterData: true },
  );
}"""


def test_a_still_robot_is_not_written_into_the_table_again_each_frame(
    page: Any, served: Served
) -> None:
    # The table wrote its four live cells of each motor at every frame (20 a second), values
    # unchanged or not: the page laid itself out again 20 times a second for nothing.
    served.robot.compliant = True
    page.evaluate(COUNT_WRITES)
    counted = "() => [window.__writes, window.poppy.stats.frames - window.__framesAtStart]"
    eventually(lambda: page.evaluate(counted)[1] >= 20, "20 frames of the stream")
    writes, frames = page.evaluate(counted)
    cells = 4 * len(served.robot.motors)  # what each frame used to rewrite
    # a value that does change (a temperature, a load) is still written: two cells a frame at most
    assert writes < 2 * frames, f"{writes} writes in {frames} frames (each rewrote {cells})"


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


def test_a_poll_asked_before_a_compliance_click_does_not_undo_it(page: Any, served: Served) -> None:
    # The page polls the motors' details every 0.5 s: one asked before the click and answered
    # after it carries the old compliance, and used to put the box back under the user's click
    # (Playwright's uncheck then failed: "clicking the checkbox did not change its state").
    robot = served.robot
    robot.compliant = True
    box = "#motor-m3 input[type=checkbox]"
    eventually(lambda: page.is_checked(box), "m3 shown compliant")
    stale: list[tuple[Any, Any]] = []  # the first poll, answered now (m3 compliant)
    later: list[Any] = []  # the polls after it, held unanswered until let go

    def hold(route: Any) -> None:
        if stale:
            later.append(route)
        else:
            stale.append((route, route.fetch()))

    page.route("**/api/v1/web/motors", hold)
    try:
        eventually(lambda: page.wait_for_timeout(50) or stale, "a poll to be held")
        page.uncheck(box)
        eventually(lambda: robot.m3.compliant is False, "m3 stiff")
        eventually(lambda: page.wait_for_timeout(50) or later, "a poll after the click")
        for route in later:  # the answers after the click come first: m3 stiff
            route.continue_()
        later.clear()
        page.wait_for_timeout(300)
        assert not page.is_checked(box)
        route, old = stale[0]
        route.fulfill(response=old)  # the poll asked before the click is answered last
        page.wait_for_timeout(150)  # handled at once (the next poll is held)
        assert not page.is_checked(box)
    finally:
        for route in later:
            route.continue_()
        page.unroute("**/api/v1/web/motors")  # and lets the polls held meanwhile go
    robot.compliant = True


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


def test_a_compliant_motor_says_so_where_its_goal_is_set(page: Any, served: Served) -> None:
    robot = served.robot
    robot.compliant = True
    note = page.locator("#motor-m4 .free-note")
    eventually(lambda: note.is_visible(), "m4's goal cell to say it is compliant")
    assert "make it stiff" in note.inner_text()
    slider = page.locator("#motor-m4 input[type=range]")
    slider.focus()
    page.keyboard.press("ArrowRight")
    slider.dispatch_event("change")  # refused (409): the status line says why
    status = page.locator("#message")
    eventually(lambda: "m4 is compliant" in status.inner_text(), "the refusal's reason shown")
    box = "#motor-m4 input[type=checkbox]"  # the page's poll has shown m4 compliant
    eventually(lambda: page.is_checked(box), "m4's compliance box checked")
    page.uncheck(box)
    eventually(lambda: not note.is_visible(), "the note gone once m4 is stiff")
    eventually(lambda: robot.m4.compliant is False, "m4 stiff")
    robot.compliant = True


def unfold(page: Any, primitive: str) -> None:
    """Shows ``primitive``'s properties: its ⋯ button clicked until it says it is expanded, as a
    person clicks again. One click was lost on a loaded machine (a loaded run: the properties
    stayed hidden for 30 s); at this width nothing above the row moves once the page is live
    (test_web_page_layout), so where it went is not known."""
    fold = f"button[aria-label^='more of {primitive}']"

    def expanded() -> bool:
        if page.get_attribute(fold, "aria-expanded") != "true":
            page.click(fold)
        return page.get_attribute(fold, "aria-expanded") == "true"

    eventually(expanded, f"{primitive}'s properties shown")


def test_a_primitive_starts_and_stops_from_its_buttons(page: Any, served: Served) -> None:
    robot = served.robot
    unfold(page, "sinus")
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


def overlap(a: dict[str, float], b: dict[str, float]) -> bool:
    """True when two bounding boxes share some area."""
    apart_x = a["x"] + a["width"] <= b["x"] or b["x"] + b["width"] <= a["x"]
    apart_y = a["y"] + a["height"] <= b["y"] or b["y"] + b["height"] <= a["y"]
    return not (apart_x or apart_y)


def test_one_click_on_stop_stops_and_holds_then_offers_compliant(page: Any, served: Served) -> None:
    robot = served.robot
    robot.compliant = True
    robot.sinus.start()
    eventually(robot.sinus.is_alive, "sinus running")
    page.click("#stop-all")  # one click and nothing else
    eventually(lambda: not robot.sinus.is_alive(), "one click on Stop to stop sinus")
    eventually(lambda: not any(m.compliant for m in robot.motors), "the motors held")
    # what follows is a choice that blocks nothing: the page works with it open
    eventually(lambda: page.is_visible("#stop-dialog"), "the choice after Stop")
    assert not page.evaluate("() => document.getElementById('stop-dialog').matches(':modal')")
    assert "1 primitive and 0 moves stopped" in page.inner_text("#stop-dialog")
    for width in (390, 1280):  # the choice covers no part of Stop, on a phone either
        page.set_viewport_size({"width": width, "height": 900})
        stop = page.locator("#stop-all").bounding_box()
        choice = page.locator("#stop-dialog").bounding_box()
        assert stop and choice
        assert not overlap(stop, choice), f"the choice covers Stop at {width} px: {choice}, {stop}"
    page.click("button[aria-label='start cosinus']")
    eventually(robot.cosinus.is_alive, "cosinus started with the choice still open")
    # keyboard: Escape alone stops
    page.keyboard.press("Escape")
    eventually(lambda: not robot.cosinus.is_alive(), "Escape alone to stop cosinus")
    page.click("#stop-compliant")
    eventually(lambda: robot.compliant, "the motors compliant when asked after")
    assert not page.is_visible("#stop-dialog")
    eventually(lambda: "Stop from the web page" in page.inner_text("#log-lines"), "the log line")


LINES = """cells => cells.map(cell => {
  const range = document.createRange();
  range.selectNodeContents(cell);
  return new Set([...range.getClientRects()].map(r => Math.round(r.top))).size;
})"""


def move_row(page: Any, name: str) -> dict[str, str]:
    """A row of the move list by column heading."""
    return dict(
        page.evaluate(
            """name => {
      const heads = [...document.querySelectorAll("#move-table thead th")].map(t => t.textContent);
      const cells = [...document.getElementById(`move-${name}`).children];
      return Object.fromEntries(heads.map((h, i) => [h, cells[i].textContent]));
    }""",
            name,
        )
    )


@pytest.fixture
def timed(page: Any) -> Iterator[str]:
    """A move of 2.98 s in the library (150 frames at 50 Hz), shown in the page's list."""
    from poppy_core.motion import Move, delete_move, save_move

    times = np.arange(150) / 50.0
    save_move(Move(50, ["m1", "m2"], np.stack([30 * np.sin(2 * times), 10 * times], 1)), "timed")
    eventually(lambda: page.query_selector("#move-timed"), "the move in the list")
    yield "timed"
    delete_move("timed")


def test_the_move_list_gives_durations(page: Any, timed: str) -> None:
    row = move_row(page, timed)
    assert "duration" in row, f"no duration column: {sorted(row)}"
    assert row["duration"].replace("\xa0", " ") == "2.98 s"  # as `poppy moves list` says it
    assert re.fullmatch(r"\d+\.\d kB", row["size"].replace("\xa0", " ")), row["size"]


PLAY_AGAIN_S = 4.0  # more than the replay of `timed` (2.98 s)


def test_a_replay_starting_and_ending_keeps_the_row_as_it_was(
    page: Any, served: Served, timed: str
) -> None:
    served.robot.compliant = False
    page.fill("[aria-label='timed speed']", "1.0")  # drawn again, the row would say "1"
    delete = page.query_selector("button[aria-label='delete timed']")
    clicked = [-PLAY_AGAIN_S]

    def plays() -> bool:
        # a click can land elsewhere while the panels above still fill (see `unfold`): not
        # seen playing a replay's length after it, the ▶ button is clicked again
        if "▶" in page.inner_text("#move-timed th"):
            return True
        if time.monotonic() - clicked[0] > PLAY_AGAIN_S:
            page.click("button[aria-label='play timed']")
            clicked[0] = time.monotonic()
        return False

    eventually(plays, "the row to say it plays")
    eventually(lambda: "▶" not in page.inner_text("#move-timed th"), "the replay to end")
    # marked in place: the typed speed is kept, and the buttons are the ones a click aimed at
    assert page.input_value("[aria-label='timed speed']") == "1.0"
    assert delete is not None and delete.evaluate("button => button.isConnected")
    served.robot.compliant = True


def test_no_value_of_the_move_list_wraps(page: Any, timed: str) -> None:
    for width in (1280, 390):  # desktop, then a phone
        page.set_viewport_size({"width": width, "height": 900})
        heads = page.eval_on_selector_all("#move-table thead th", "ts => ts.map(t => t.innerText)")
        cells = page.eval_on_selector_all(f"#move-{timed} > *", LINES)
        lines = {h: n for h, n in zip(heads, cells, strict=True) if h in ("size", "duration")}
        assert lines and set(lines.values()) == {1}, f"a value split over lines at {width}: {lines}"
    scroller = "document.getElementById('move-table').parentElement"
    wide, room = page.evaluate(f"() => [{scroller}.scrollWidth, {scroller}.clientWidth]")
    assert wide <= room, f"the move list is {wide} px wide in {room} px on a phone"


def test_the_plot_has_a_time_axis_in_seconds(page: Any, timed: str) -> None:
    page.click(f"button[aria-label='plot {timed}']")
    eventually(lambda: page.is_visible("#plot polyline"), "the plot")
    assert "time (s)" in page.inner_text("#plot")
    texts = page.eval_on_selector_all(
        "#plot-svg text", "ts => ts.map(t => [t.textContent, Number(t.getAttribute('x'))])"
    )
    marks = [(float(text), x) for text, x in texts if re.fullmatch(r"[\d.]+", text)]
    assert len(marks) >= 3 and marks[0][0] == 0, texts
    assert [v for v, _ in marks] == sorted(v for v, _ in marks)
    assert 1.5 <= marks[-1][0] <= 2.98, marks
    points = page.get_attribute("#plot polyline", "points") or ""
    start, end = (float(p.split(",")[0]) for p in (points.split()[0], points.split()[-1]))
    for seconds, x in marks:  # each tick where that time is drawn
        assert abs(x - (start + (end - start) * seconds / 2.98)) < 1.0, (seconds, x)


def test_a_clamped_goal_is_shown(page: Any, served: Served) -> None:
    motor = served.robot.m5
    old = motor.angle_limit
    motor.angle_limit = (-10.0, 10.0)  # narrowed after the page drew its slider (-90..90)
    motor.compliant = False  # a compliant motor's goal is refused (409)
    try:
        slider = page.locator("#motor-m5 input[type=range]")
        slider.fill("60")
        slider.dispatch_event("change")
        eventually(lambda: "clamped" in page.inner_text("#message"), "the clamp")
        assert "m5 → 10° (clamped to the angle limits)" in page.inner_text("#message")
        assert "refused" not in (page.get_attribute("#motor-m5", "class") or "")
        eventually(lambda: abs(motor.goal_position - 10.0) < 0.5, "the goal clamped to the limit")
    finally:
        motor.angle_limit = old
        motor.compliant = True


def test_the_sensors_are_shown_and_a_lost_camera_says_why(
    page: Any, served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    eventually(lambda: "camera" in page.inner_text("#sensors"), "the sensors listed")
    assert page.get_attribute("#sensors li:first-child", "class") == "ok"
    camera = served.robot.sensor("camera")
    why = "/dev/video0 does not exist: plug the camera in"
    lost = dataclasses.replace(camera.health(), connected=False, last_error=why)
    monkeypatch.setattr(camera, "health", lambda: lost)  # as an unplugged camera's
    eventually(
        lambda: "lost · /dev/video0 does not exist" in page.inner_text("#sensors"),
        "the lost camera shown (the page refreshes every 5 s)",
    )
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
    # the page then opens its stream: under two busy loops and two workers this once took over
    # the usual 30 s (a wait, not a speed check)
    tab.wait_for_function(LIVE, timeout=2 * WAIT_S * 1000)
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
    from poppy_core import from_profile

    yield from serve_robot(from_profile("ergo-jr", sim=True))


def test_chain_jog(tab: tuple[Any, list[str]], creature: Served) -> None:
    tab, _ = tab
    tab.set_viewport_size({"width": 1280, "height": 900})
    tab.goto(creature.url + "/")
    tab.wait_for_function(READY)
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
    # the Ergo Jr's chain keeps pypot's name in the URLs, and is shown as what it is
    eventually(lambda: tab.inner_text("#chain-chain h3") == "arm", "the chain shown as arm")
    tab.goto("about:blank")
    robot.compliant = True


def test_the_notes_of_the_server_are_shown(page: Any, served: Served) -> None:
    from poppy_core.assembly.server_builders import SNAP_ONLINE_NOTE
    from poppy_core.server.web import add_note

    add_note(served.app, "snap", SNAP_ONLINE_NOTE)  # as `serve --snap` without a download
    try:
        page.reload()
        page.wait_for_function(READY)
        assert "poppy snap download" in page.inner_text("#note-snap")
    finally:
        served.app.state.web_notes.clear()


def test_a_refusal_of_a_token_replaced_meanwhile_asks_nothing(
    browser: Any, with_token: Served
) -> None:
    # A call sent with a wrong token whose 401 comes back after the right token was entered (a
    # busy server answers late) tries the new token; it used to ask for the token again, and
    # the page then waited on that dialog.
    context = browser.new_context()
    tab = context.new_page()
    tab.set_default_timeout(WAIT_S * 1000)
    held: list[Any] = []
    answered: list[tuple[str, str | None, int]] = []

    def hold_one(route: Any) -> None:
        if not held and route.request.headers.get("authorization") == "Bearer wrong":
            held.append(route)  # let through once the right token is in
        else:
            route.continue_()

    tab.route("**/api/v1/**", hold_one)
    tab.on(
        "response",
        lambda r: answered.append((r.url, r.request.headers.get("authorization"), r.status)),
    )
    tab.goto(with_token.url + "/")
    tab.wait_for_selector("#token-dialog[open]")
    tab.fill("#token-input", "wrong")
    tab.click("#token-ok")
    tab.wait_for_selector("#token-dialog[open]")  # the other calls were refused
    assert held, "no call was sent with the wrong token"
    tab.fill("#token-input", "s3cret-page")
    tab.click("#token-ok")
    tab.wait_for_selector("#token-dialog", state="hidden")
    url = held[0].request.url
    held[0].continue_()

    def retried() -> bool:
        tab.wait_for_timeout(20)  # lets Playwright deliver its events
        return (url, "Bearer s3cret-page", 200) in answered

    eventually(retried, "the refused call tried again with the right token")
    assert (url, "Bearer wrong", 401) in answered
    tab.wait_for_function(LIVE, timeout=2 * WAIT_S * 1000)
    assert not tab.is_visible("#token-dialog")
    context.close()
