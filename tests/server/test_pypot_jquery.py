"""A page written for pypot works in a real browser: jQuery calls to pypot's routes, from another
origin, parsed with ``JSON.parse`` as the Poppy pages do (puppet-master's move recorder).

jQuery hands a callback a parsed object when the answer is typed JSON and a string otherwise;
pypot's answers were ``text/html``, so those pages ``JSON.parse`` what they get. The page
(``data/pypot_jquery_page.html``, with the real jQuery of ``data/jquery/``) is served on its own
port of 127.0.0.1 and allowed by the robot's origin rules, as ``poppy serve --cors`` would.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

from poppy_core.server import OriginPolicy
from tests.helpers.chromium import launched, needs_chromium
from tests.helpers.server import Served, serve
from tests.helpers.waiting import eventually

pytestmark = needs_chromium

DATA = Path(__file__).parent / "data"
FILES = {
    "/": (DATA / "pypot_jquery_page.html", "text/html; charset=utf-8"),
    "/jquery.min.js": (DATA / "jquery" / "jquery-3.7.1.min.js", "text/javascript"),
}
WAIT_S = 30.0


class PageHandler(BaseHTTPRequestHandler):
    """Serves the page and jQuery (the query string is the page's own)."""

    def do_GET(self) -> None:
        found = FILES.get(self.path.split("?")[0])
        if found is None:
            self.send_error(404)
            return
        body = found[0].read_bytes()
        self.send_response(200)
        self.send_header("Content-Type", found[1])
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: Any) -> None:
        pass


@pytest.fixture(scope="module")
def page_server() -> Iterator[str]:
    server = ThreadingHTTPServer(("127.0.0.1", 0), PageHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


@pytest.fixture(scope="module")
def robot_server(moves_folder: str, page_server: str) -> Iterator[Served]:
    yield from serve(moves_folder, policy=OriginPolicy(origins=[page_server]))


@pytest.fixture
def page(page_server: str, robot_server: Served) -> Iterator[Any]:
    errors: list[str] = []
    for browser in launched():
        opened = browser.new_page()
        opened.set_default_timeout(WAIT_S * 1000)
        opened.on("pageerror", lambda error: errors.append(str(error)))
        opened.goto(f"{page_server}/?api={robot_server.url}")
        yield opened
    assert not errors, errors  # JSON.parse of an object throws here


def texts(page: Any, selector: str) -> list[str]:
    found = page.eval_on_selector_all(selector, "nodes => nodes.map(n => n.textContent)")
    assert isinstance(found, list)
    return found


def test_the_lists_fill(page: Any) -> None:
    assert eventually(lambda: texts(page, "#aliases option") == ["base", "tip"], WAIT_S)
    assert eventually(lambda: texts(page, "#group li") == ["m1", "m2", "m3"], WAIT_S)


def test_a_motor_turns_stiff_and_compliant(page: Any, robot_server: Served) -> None:
    robot = robot_server.robot
    page.evaluate("() => setCompliant('m3', false)")
    assert eventually(lambda: robot.m3.compliant is False, WAIT_S)
    page.evaluate("() => setCompliant('m3', true)")
    assert eventually(lambda: robot.m3.compliant is True, WAIT_S)


def test_a_move_is_recorded_listed_played_and_stopped(page: Any, robot_server: Served) -> None:
    robot = robot_server.robot
    moves = robot_server.app.state.service.moves
    robot.compliant = False
    robot.goto_position({"m1": -20.0}, 0.5, wait=True)
    page.evaluate("() => startRecording('jq_wave', ['m1', 'm2'])")
    assert eventually(lambda: moves.recording() == ["jq_wave"], WAIT_S)
    robot.goto_position({"m1": 20.0}, 1.0, wait=True)
    page.evaluate("() => saveRecording('jq_wave')")  # and asks for the list at once
    assert eventually(lambda: moves.recording() == [] and "jq_wave" in moves.names(), WAIT_S)
    assert eventually(lambda: page.evaluate("() => window.listsLoaded") == 1, WAIT_S)
    assert "jq_wave" in texts(page, "#moves option")  # the list answered after the save

    page.evaluate("() => play('jq_wave', 0.1)")  # 10 times slower: still playing when stopped
    assert eventually(lambda: page.evaluate("() => window.sawPlayer"), WAIT_S)
    assert moves.playing() == ["jq_wave"]
    assert page.inner_text("#state") == "playing"  # the first poll already saw the player
    assert eventually(lambda: robot.m1.goal_position < 15.0, WAIT_S)  # on its way back to -20
    page.evaluate("() => stop('jq_wave')")
    assert eventually(lambda: page.inner_text("#state") == "ended", WAIT_S)
    assert moves.playing() == []
    robot.compliant = True
