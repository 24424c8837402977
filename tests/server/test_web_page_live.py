"""The home page in chromium when the stream stops and comes back, and what it says of its rate.

The page must never show a robot it no longer hears from as if it were live: with the server
gone, everything is greyed out and every control is off; the server back on the same port, the
stream reconnects and the controls work again.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from typing import Any

import pytest

from poppy_core import from_profile
from poppy_core.robot import Robot
from poppy_core.server import ServerThread, create_app
from tests.helpers.chromium import new_tab
from tests.server.test_web_page import (  # noqa: F401 (browser is a fixture)
    LIVE,
    WAIT_S,
    browser,
    eventually,
)

# a control of each kind in each part of the page (all off while the stream is down)
CONTROLS = [
    "#stop-all",
    "#motor-m2 input[type=checkbox]",
    "#motor-m2 input[type=range]",
    "#motor-m2 select",
    "button[aria-label='robot: stiff']",
    "button[aria-label='start sinus']",
    "#record-start",
    "#record-name",
]


@pytest.fixture
def robot(moves_folder: str) -> Iterator[Robot]:
    made = from_profile("ergo-jr", sim=True)
    try:
        yield made
    finally:
        made.close()


def offline_look(tab: Any) -> dict[str, Any]:
    """What says the page is live or not: the body's class, the banner, the greying filter."""
    return dict(
        tab.evaluate(
            """() => ({
        offline: document.body.classList.contains("offline"),
        banner: Boolean(document.getElementById("offline")?.checkVisibility()),
        filter: getComputedStyle(document.getElementById("live") ?? document.body).filter,
        rate: document.getElementById("rate").textContent,
        dots: getComputedStyle(document.querySelector("#motor-m1 td.online")).color,
      })"""
        )
    )


def test_the_page_greys_out_while_the_server_is_gone_and_comes_back(
    browser: Any,  # noqa: F811 (the fixture imported above)
    robot: Robot,
) -> None:
    first = ServerThread(create_app(robot)).start()
    port = first.port
    context, tab = new_tab(browser, WAIT_S * 1000)
    try:
        tab.goto(first.url + "/")
        tab.wait_for_function(LIVE)
        eventually(lambda: tab.is_enabled("#stop-all"), "the page live")
        live = offline_look(tab)
        assert not live["offline"] and not live["banner"] and live["filter"] == "none"
        assert all(tab.is_enabled(selector) for selector in CONTROLS)

        first.stop()  # the server is gone
        eventually(lambda: tab.inner_text("#conn") == "disconnected", "the badge to say it")
        gone = offline_look(tab)
        assert gone["offline"] and gone["banner"], gone
        assert "grayscale" in gone["filter"], gone  # the green dots and "ok" are grey
        assert not gone["rate"].startswith("live"), gone["rate"]
        still_on = [selector for selector in CONTROLS if tab.is_enabled(selector)]
        assert not still_on, f"controls still enabled with the server gone: {still_on}"
        uptime = tab.inner_text("#uptime")
        time.sleep(1.5)  # the uptime is not counted on with nobody to count it
        assert tab.inner_text("#uptime") == uptime

        second = ServerThread(create_app(robot), port=port).start()  # back on the same port
        try:
            eventually(lambda: not offline_look(tab)["offline"], "the stream to reconnect")
            back = offline_look(tab)
            assert not back["banner"] and back["filter"] == "none"
            assert tab.inner_text("#conn") == "connected"
            eventually(
                lambda: all(tab.is_enabled(selector) for selector in CONTROLS),
                "every control enabled again",
            )
            # and they work: the page drives the robot served again
            robot.compliant = True
            tab.uncheck("#motor-m2 input[type=checkbox]")
            eventually(lambda: robot.m2.compliant is False, "m2 stiff after the reconnect")
        finally:
            second.stop()
    finally:
        context.close()
        first.stop()
        robot.compliant = True


def test_one_update_a_second_is_said_in_the_singular(
    browser: Any,  # noqa: F811 (the fixture imported above)
    robot: Robot,
) -> None:
    """The stream thinned to one frame a second on its way to the page: "1 update/s"."""
    server = ServerThread(create_app(robot)).start()
    context, tab = new_tab(browser, WAIT_S * 1000)
    last = [0.0]

    def thin(socket: Any) -> None:
        upstream = socket.connect_to_server()

        def forward(message: Any) -> None:
            now = time.monotonic()
            if now - last[0] >= 1.0:
                last[0] = now
                socket.send(message)

        upstream.on_message(forward)

    try:
        tab.route_web_socket(re.compile(r".*/api/v1/ws.*"), thin)
        tab.goto(server.url + "/")
        tab.wait_for_function(LIVE)
        said: list[str] = []

        def singular() -> bool:
            said.append(tab.inner_text("#rate"))
            return said[-1] == "live · 1 update/s"

        eventually(singular, "'live · 1 update/s' in the page")
        assert not [text for text in said if "1 updates" in text], said
    finally:
        context.close()
        server.stop()


def test_a_stream_gone_silent_counts_as_lost(
    browser: Any,  # noqa: F811 (the fixture imported above)
    robot: Robot,
) -> None:
    """A server that stops sending without closing (a network down): greyed out, then back."""
    server = ServerThread(create_app(robot)).start()
    context, tab = new_tab(browser, WAIT_S * 1000)
    silent = [False]
    sockets: list[Any] = []

    def relay(socket: Any) -> None:
        sockets.append(socket)
        upstream = socket.connect_to_server()
        upstream.on_message(lambda message: None if silent[0] else socket.send(message))

    try:
        tab.route_web_socket(re.compile(r".*/api/v1/ws.*"), relay)
        tab.goto(server.url + "/")
        tab.wait_for_function(LIVE)
        eventually(lambda: tab.is_enabled("#stop-all"), "the page live")
        silent[0] = True  # frames stop, the socket stays open
        eventually(lambda: offline_look(tab)["offline"], "the silent stream counted as lost")
        assert not tab.is_enabled("#motor-m2 input[type=checkbox]")
        silent[0] = False
        eventually(lambda: not offline_look(tab)["offline"], "the stream back")
        assert len(sockets) >= 2, "the page did not open a new stream"
        eventually(lambda: tab.is_enabled("#motor-m2 input[type=checkbox]"), "controls back")
    finally:
        context.close()
        server.stop()
