"""The teacher's page (`poppy fleet serve`): two named robots served on Zenoh (loopback, explicit
endpoints, scouting off), the page in Debian's chromium: their cards, a move played and a
primitive run on the selection with the shared start, one Stop for all; the token and origin
rules of a robot's page; the camera's frame on demand; the command's own process."""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import pytest

from poppy_core.motion.move import Move
from poppy_core.motion.move_library import save_move
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings
from tests.helpers.chromium import launched, needs_chromium, new_tab
from tests.helpers.cli import ENV, POPPY, command_env
from tests.helpers.processes import read_until, reap
from tests.helpers.waiting import eventually, http_timeout, scaled
from tests.helpers.zenoh_served import TOKEN, Served, connect_to

pytest.importorskip("zenoh")
from poppy_core.server.teacher import TeacherServer, exposure

WAIT_S = 30.0
MOVE = "wave"
MOVE_S = 20.0
"""Long enough to be seen playing on both robots before the Stop."""


def _wave() -> Move:
    """m1 out to 20° and back, slowly, for ``MOVE_S`` seconds."""
    frames = int(MOVE_S * 10)
    angles = 20.0 * np.sin(np.linspace(0.0, np.pi, frames))
    return Move(10.0, ["m1"], angles.reshape(-1, 1))


@pytest.fixture(scope="module")
def robots(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Served, Served]]:
    folder = tmp_path_factory.mktemp("moves")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("POPPY_MOVES_DIR", str(folder))
        save_move(_wave(), MOVE)
        jr1, jr2 = Served("jr1"), Served("jr2")
        try:
            yield jr1, jr2
        finally:
            jr1.close()
            jr2.close()


@pytest.fixture(scope="module")
def teacher(robots: tuple[Served, Served]) -> Iterator[TeacherServer]:
    settings = ZenohSettings(connect=connect_to(*robots))
    with TeacherServer(lambda: Fleet(settings, token=TOKEN), token=TOKEN) as server:
        yield server


def _client(teacher: TeacherServer, token: str | None = TOKEN) -> httpx.Client:
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    return httpx.Client(base_url=teacher.url, headers=headers, timeout=http_timeout(10))


def _cards(teacher: TeacherServer) -> dict[str, dict[str, Any]]:
    with _client(teacher) as http:
        return {card["name"]: card for card in http.get("/api/v1/fleet/robots").json()}


def _ready(teacher: TeacherServer) -> dict[str, dict[str, Any]]:
    """The two cards, once both robots are described and well."""

    seen: list[dict[str, dict[str, Any]]] = []

    def both() -> bool:
        seen.append(_cards(teacher))
        cards = seen[-1]
        return all(cards.get(n, {}).get("described") and cards[n]["ok"] for n in ("jr1", "jr2"))

    assert eventually(both, timeout_s=WAIT_S, interval_s=0.1), f"two well robots: {seen[-1]}"
    return seen[-1]


def _idle(robots: tuple[Served, Served]) -> None:
    for served in robots:
        service = served.servers.service
        service.moves.stop_all()
        for name in service.running_primitives():
            service.primitive(name).halt(wait=True)


def _playing(served: Served) -> list[str]:
    return list(served.servers.service.moves.playing())


def _running(served: Served) -> list[str]:
    return list(served.servers.service.running_primitives())


# -- the API, its token and origin rules ------------------------------------------------------


def test_the_cards_name_both_robots_with_creature_health_and_moves(
    teacher: TeacherServer,
) -> None:
    cards = _ready(teacher)
    assert sorted(cards) == ["jr1", "jr2"]
    for card in cards.values():
        assert card["creature"] == "ergo-jr" and card["motors"] == 6
        assert card["health"] == "ok" and card["alive"] is True
        assert MOVE in card["moves"] and "dance" in card["primitives"]
        assert card["temperature"] is not None and card["hottest"] is not None
        assert card["cameras"] == [] and card["no_camera"].startswith("No camera")


def test_the_token_is_needed_for_the_api_and_the_stream_not_the_page(
    teacher: TeacherServer,
) -> None:
    with _client(teacher, token=None) as http:
        refused = http.get("/api/v1/fleet/robots")
        assert refused.status_code == 401
        assert "token" in refused.json()["detail"]
        assert http.post("/api/v1/fleet/stop", json={}).status_code == 401
        assert http.get("/").status_code == 200  # the page loads, to ask for the token
        assert http.get("/teacher/teacher.js").status_code == 200
        assert http.get("/web/api.js").status_code == 200
    with _client(teacher, token="wrong-token-123") as http:
        assert http.get("/api/v1/fleet/robots").status_code == 401
    from websockets.exceptions import InvalidStatus

    with pytest.raises(InvalidStatus) as refused_stream:
        _handshake(teacher, protocols=None)
    assert refused_stream.value.response.status_code == 401
    assert _handshake(teacher, protocols=[f"poppy-token.{TOKEN.encode().hex()}"])


def _handshake(teacher: TeacherServer, protocols: list[str] | None) -> dict[str, Any]:
    """The first message of the stream (raises when the handshake is refused)."""
    import json

    from websockets.sync.client import connect

    url = teacher.url.replace("http://", "ws://") + "/api/v1/fleet/ws"
    with connect(url, subprotocols=protocols, open_timeout=scaled(10)) as socket:  # type: ignore[arg-type]
        message: dict[str, Any] = json.loads(socket.recv(timeout=scaled(10)))
        return message


def test_a_foreign_origin_and_a_foreign_host_are_refused_and_nothing_moves(
    teacher: TeacherServer, robots: tuple[Served, Served]
) -> None:
    _ready(teacher)
    _idle(robots)
    jr1 = robots[0]
    jr1.servers.service.primitive("dance").start()
    try:
        with _client(teacher) as http:
            foreign = http.post(
                "/api/v1/fleet/stop", json={}, headers={"Origin": "http://evil.example"}
            )
            assert foreign.status_code == 403
            assert "--cors http://evil.example" in foreign.json()["detail"]
            assert "poppy fleet serve" in foreign.json()["detail"]
            rebound = http.get("/api/v1/fleet/robots", headers={"Host": "evil.example"})
            assert rebound.status_code == 400
            cross = http.post(
                "/api/v1/fleet/stop", json={}, headers={"Sec-Fetch-Site": "cross-site"}
            )
            assert cross.status_code == 403
            assert _running(jr1) == ["dance"]  # nothing stopped it
            own = http.post("/api/v1/fleet/stop", json={}, headers={"Origin": teacher.url})
            assert own.status_code == 200, own.text
        assert eventually(lambda: _running(jr1) == [], timeout_s=WAIT_S)
    finally:
        _idle(robots)


def test_bad_commands_are_one_line_refusals(
    teacher: TeacherServer, robots: tuple[Served, Served]
) -> None:
    _ready(teacher)
    with _client(teacher) as http:
        empty = http.post("/api/v1/fleet/play", json={"move": MOVE, "robots": []})
        assert empty.status_code == 422
        bad = http.post("/api/v1/fleet/run", json={"primitive": "dance", "robots": ["no way"]})
        assert bad.status_code == 422 and "not a robot name" in bad.json()["detail"]
        unknown = http.post("/api/v1/fleet/play", json={"move": "nope", "robots": ["jr1", "jr2"]})
        assert unknown.status_code == 200
        outcomes = {o["name"]: o for o in unknown.json()["outcomes"]}
        assert not outcomes["jr1"]["ok"] and "nope" in outcomes["jr1"]["message"]
        assert not outcomes["jr2"]["ok"]
        away = http.get("/api/v1/fleet/robots/jr1/cameras/nope/frame.jpg")
        assert away.status_code == 404 and away.json()["detail"].startswith("jr1: ")
    assert _playing(robots[0]) == [] and _playing(robots[1]) == []


def test_a_camera_frame_is_asked_of_the_robot_over_zenoh(teacher: TeacherServer) -> None:
    _ready(teacher)
    with _client(teacher) as http:
        # an ideal simulation's camera gives black frames: asked anyway, it answers a JPEG
        frame = http.get("/api/v1/fleet/robots/jr2/cameras/camera/frame.jpg")
    assert frame.status_code == 200, frame.text
    assert frame.headers["content-type"] == "image/jpeg"
    assert frame.content[:3] == b"\xff\xd8\xff"


def test_exposure_warns_off_loopback_without_a_token_and_for_any_origin() -> None:
    assert exposure("127.0.0.1", None) == []
    assert exposure("0.0.0.0", "a-token-of-16chars") == []
    (line,) = exposure("0.0.0.0", None)
    assert "without a token" in line and "every robot" in line
    (line,) = exposure("127.0.0.1", None, ("*",))
    assert "every web page" in line


# -- the page in chromium ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    yield from launched()


@pytest.fixture(scope="module")
def tab(browser: Any) -> Iterator[Any]:
    """The module's tab, where each test opens its page afresh (a new context costs the browser
    about three times what loading a page in this one does); each test leaves it on about:blank."""
    context, page = new_tab(browser, WAIT_S * 1000)
    yield page
    context.close()


@needs_chromium
def test_the_page_plays_a_move_on_both_robots_together_and_stop_stops_both(
    tab: Any, teacher: TeacherServer, robots: tuple[Served, Served]
) -> None:
    _ready(teacher)
    _idle(robots)
    jr1, jr2 = robots
    page = tab
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.on(
        "console",
        lambda message: (
            errors.append(message.text) if "Content Security Policy" in message.text else None
        ),
    )
    try:
        page.goto(teacher.url + "/")
        page.wait_for_selector("#token-dialog[open]")  # the page asks for the token
        page.fill("#token-input", TOKEN)
        page.click("#token-ok")
        page.wait_for_function("() => window.teacher && window.teacher.stats.frames > 0")
        for name in ("jr1", "jr2"):
            card = f"#robot-{name}"
            page.wait_for_selector(f"{card} .health.ok")
            assert page.inner_text(f"{card} .name") == name
            assert page.inner_text(f"{card} .creature") == "ergo-jr"
            assert page.inner_text(f"{card} .health") == "ok"
            assert "°C" in page.inner_text(f"{card} .temperature")
            assert page.inner_text(f"{card} .doing") == "nothing"
        assert page.is_disabled("#play")  # nothing selected yet
        page.check("#robot-jr1 input.pick")
        page.check("#robot-jr2 input.pick")
        assert page.inner_text("#selected-count") == "jr1, jr2"
        page.select_option("#move-choice", MOVE)
        page.click("#play")
        assert eventually(
            lambda: _playing(jr1) == [MOVE] and _playing(jr2) == [MOVE], timeout_s=WAIT_S
        ), "both robots playing"
        assert eventually(
            lambda: (
                page.inner_text("#robot-jr1 .doing") == f"playing {MOVE}"
                and page.inner_text("#robot-jr2 .doing") == f"playing {MOVE}"
            ),
            timeout_s=WAIT_S,
        ), "the cards say what the robots do (live over Zenoh)"
        # the page says so when the fleet's answer arrives, which may come after the cards (the
        # robots start at the shared time; their answers are gathered, then sent back)
        said = f"play {MOVE}: jr1, jr2, started together"
        assert eventually(lambda: page.inner_text("#message") == said, timeout_s=WAIT_S), (
            page.inner_text("#message")
        )
        assert page.inner_text("#robot-jr1 .outcome") == f"play {MOVE}: done"
        page.click("#stop-all")
        assert eventually(lambda: not _playing(jr1) and not _playing(jr2), timeout_s=WAIT_S), (
            "both stopped"
        )
        assert eventually(
            lambda: page.inner_text("#robot-jr1 .doing") == "nothing", timeout_s=WAIT_S
        )
        # a primitive on one robot of the selection only
        page.uncheck("#robot-jr2 input.pick")
        page.select_option("#primitive-choice", "dance")
        page.click("#run")
        assert eventually(lambda: _running(jr1) == ["dance"], timeout_s=WAIT_S), "jr1 dancing"
        assert _running(jr2) == []
        page.keyboard.press("Escape")  # the Stop's key, as on a robot's page
        assert eventually(lambda: _running(jr1) == [], timeout_s=WAIT_S), "jr1 stopped"
    finally:
        page.goto("about:blank")
        _idle(robots)
    assert not errors, errors


@needs_chromium
def test_a_foreign_page_cannot_drive_the_fleet_from_the_browser(
    tab: Any, teacher: TeacherServer, robots: tuple[Served, Served]
) -> None:
    # a page of another origin (a second server on loopback, another port) posts to the
    # teacher's Stop with the token it somehow knows: the browser sends its Origin, refused
    from starlette.applications import Starlette
    from starlette.responses import HTMLResponse
    from starlette.routing import Route

    from poppy_core.server import ServerThread

    _ready(teacher)
    jr1 = robots[0]
    jr1.servers.service.primitive("dance").start()
    script = f"""<script>
      fetch("{teacher.url}/api/v1/fleet/stop", {{method: "POST",
        headers: {{"Content-Type": "application/json", "Authorization": "Bearer {TOKEN}"}},
        body: "{{}}"}}).then(r => document.title = "status " + r.status,
                          e => document.title = "refused: " + e.message);
    </script>"""

    async def evil(request: Any) -> HTMLResponse:
        return HTMLResponse(script)

    foreign = ServerThread(Starlette(routes=[Route("/", evil)])).start()
    page = tab
    try:
        page.goto(foreign.url + "/")
        assert eventually(lambda: page.title().startswith("refused"), timeout_s=WAIT_S)
        assert _running(jr1) == ["dance"]  # still dancing
    finally:
        page.goto("about:blank")
        foreign.stop()
        _idle(robots)


# -- the command ------------------------------------------------------------------------------


def test_poppy_fleet_serve_serves_the_page_until_sigterm(
    robots: tuple[Served, Served], tmp_path: Path
) -> None:
    args = [arg for s in robots for arg in ("--zenoh-connect", s.endpoint)]
    env = dict(os.environ, **command_env({**ENV, "POPPY_TOKEN": TOKEN}))
    proc = subprocess.Popen(
        [*POPPY, "fleet", "serve", "--http-port", "0", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
    )
    try:
        assert proc.stdout is not None
        shown = read_until(proc.stdout.fileno(), "\n", WAIT_S, proc)
        assert shown.startswith("page: http://127.0.0.1:"), shown
        url = shown.split()[1].rstrip("/")
        headers = {"Authorization": f"Bearer {TOKEN}"}

        def both() -> bool:
            cards = httpx.get(
                url + "/api/v1/fleet/robots", headers=headers, timeout=http_timeout(10)
            ).json()
            return [c["name"] for c in cards if c["described"]] == ["jr1", "jr2"]

        assert eventually(both, timeout_s=WAIT_S, interval_s=0.1)
        assert httpx.get(url + "/api/v1/fleet/robots", timeout=http_timeout(10)).status_code == 401
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(scaled(WAIT_S)) == 0
        assert proc.stderr is not None
        assert "stopped" in proc.stderr.read().decode()
    finally:
        reap(proc)


def test_poppy_fleet_serve_refuses_a_bad_origin_and_a_busy_port(
    robots: tuple[Served, Served], teacher: TeacherServer
) -> None:
    from tests.helpers.cli import run_poppy

    args = ["--zenoh-connect", robots[0].endpoint]
    bad = run_poppy("fleet", "serve", "--cors", "not an origin", *args)
    assert bad.code == 2 and "not an origin" in bad.stderr and "Traceback" not in bad.stderr
    busy = run_poppy("fleet", "serve", "--http-port", str(teacher.port), *args)
    assert busy.code == 1 and "already in use" in busy.stderr, busy.stderr
    assert len(busy.stderr.strip().splitlines()) == 1


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


@needs_chromium
@pytest.mark.gl
def test_a_card_shows_the_simulated_camera_when_its_button_is_clicked(tab: Any) -> None:
    pytest.importorskip("mujoco")
    from poppy_core import from_profile
    from poppy_core.assembly import ServeSpec, serve
    from poppy_core.errors import SensorError
    from tests.helpers.zenoh_served import free_endpoint

    robot = from_profile("ergo-jr", sim="mujoco")
    try:
        robot.camera.latest(timeout_s=30)
    except SensorError as exc:
        robot.close()
        pytest.skip(f"no OpenGL for offscreen rendering here ({exc}); `make sim-deps`")
    endpoint = free_endpoint()
    servers = serve(robot, ServeSpec(zenoh=ZenohSettings(listen=(endpoint,)), name="jr3"))
    try:
        settings = ZenohSettings(connect=(endpoint,))
        with TeacherServer(lambda: Fleet(settings)) as teacher:
            page = tab
            try:
                page.goto(teacher.url + "/")
                button = page.locator("#robot-jr3 .camera button")
                button.wait_for()
                assert button.inner_text() == "Camera: camera"
                image = page.locator("#robot-jr3 .camera img")
                assert image.is_hidden()  # nothing asked before the click
                shown: list[str] = []

                def seen() -> bool:  # a new frame each click (a first one may still be black)
                    if image.is_hidden() or image.get_attribute("src") in shown:
                        return False
                    shown.append(image.get_attribute("src") or "")
                    if image.evaluate("i => i.complete && i.naturalWidth") and (
                        image.evaluate(MEAN_PIXEL) > 20
                    ):
                        return True
                    button.click()
                    return False

                button.click()
                assert eventually(seen, timeout_s=WAIT_S, interval_s=0.1), "a picture, not black"
            finally:
                page.goto("about:blank")
    finally:
        servers.stop()
        robot.close()


def test_a_robot_that_leaves_keeps_its_card_marked_gone_and_is_not_stopped(
    moves: Path,
) -> None:
    jr9 = Served("jr9", token=None)
    settings = ZenohSettings(connect=(jr9.endpoint,))
    try:
        with TeacherServer(lambda: Fleet(settings)) as teacher:
            http = httpx.Client(base_url=teacher.url, timeout=http_timeout(10))

            def card() -> dict[str, Any]:
                cards = {c["name"]: c for c in http.get("/api/v1/fleet/robots").json()}
                return cards.get("jr9", {})

            assert eventually(lambda: card().get("health") == "ok", timeout_s=WAIT_S)
            jr9.close()
            assert eventually(lambda: card().get("alive") is False, timeout_s=WAIT_S)
            assert card()["health"] == "left the network" and card()["ok"] is False
            stop = http.post("/api/v1/fleet/stop", json={})
            assert stop.status_code == 409 and stop.json()["detail"] == "no robot on Zenoh to stop"
            http.close()
    finally:
        jr9.close()
