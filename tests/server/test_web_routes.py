"""The home page's routes over real HTTP: the page and its assets, about, logs, Stop, the token."""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator

import httpx
import pytest

from poppy_core.server.web import static_folder
from tests.helpers.waiting import http_timeout
from tests.server.conftest import Served, serve


def test_the_page_and_its_assets_are_served(client: httpx.Client) -> None:
    page = client.get("/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    assert '<script type="module" src="/web/app.js">' in page.text
    assert "frame-ancestors 'none'" in page.headers["content-security-policy"]
    for asset in ("app.js", "api.js", "motors.js", "style.css", "favicon.svg"):
        answer = client.get(f"/web/{asset}")
        assert answer.status_code == 200, asset
    # every asset is local: nothing from a CDN
    for path in ("index.html", "app.js", "extras.js", "style.css"):
        with open(f"{static_folder()}/{path}", encoding="utf-8") as file:
            assert "https://" not in file.read(), path


def test_pypots_route_listing_moved_to_routes(client: httpx.Client) -> None:
    assert "/robot.json" in client.get("/routes").text


def test_about_names_the_robot_as_served_and_as_renamed(
    client: httpx.Client, served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    # `/api/v1/web/about` gave the profile as the name: a robot served --name jr1 was "ergo-jr"
    served_robot = served.app.state.settings.served
    monkeypatch.setattr(served_robot, "name", "jr1")  # what `poppy serve --name jr1` sets
    about = client.get("/api/v1/web/about").json()
    assert (about["name"], about["creature"]) == ("jr1", "ergo-jr")
    served_robot.named("jr2")  # renamed from the settings, or the mDNS name won
    assert client.get("/api/v1/web/about").json()["name"] == "jr2"


def test_about_shows_no_black_camera_and_no_dead_jupyter(
    client: httpx.Client, served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    import socket

    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        closed = probe.getsockname()[1]
    monkeypatch.setattr(served.app.state, "web_notebook_port", closed)
    monkeypatch.setattr(served.app.state, "web_notebook_seen", {})
    about = client.get("/api/v1/web/about").json()
    assert about["cameras"] == ["camera"]  # an ideal simulation's DummyCamera: black frames
    assert about["camera_views"] == [] and about["no_camera"].startswith("No camera")
    assert about["notebook"] is None  # the page links to no Jupyter


def test_about_says_what_the_robot_is(client: httpx.Client) -> None:
    about = client.get("/api/v1/web/about").json()
    assert about["name"] == "ergo-jr" and about["simulated"] is True
    assert about["links"]["API docs"] == "/docs"
    assert about["uptime_s"] >= 0
    (bus,) = about["buses"].values()
    assert bus["connected"] is True and bus["offline"] == []
    assert "camera" in about["cameras"]


def test_motor_details_and_leds(client: httpx.Client) -> None:
    details = client.get("/api/v1/web/motors").json()
    assert set(details["motors"]) == {f"m{i}" for i in range(1, 7)}
    assert details["motors"]["m2"]["angle_limit"] == [-125.0, 90.0]
    assert details["groups"] == {"base": ["m1", "m2", "m3"], "tip": ["m4", "m5", "m6"]}
    assert "leds" not in details["motors"]["m1"]
    leds = client.get("/api/v1/web/motors?leds=true").json()["motors"]["m1"]["leds"]
    assert "red" in leds and "off" in leds


def test_logs_show_what_the_server_logged(client: httpx.Client) -> None:
    logging.getLogger("poppy_core.server.test").warning("a line for the page")
    lines = client.get("/api/v1/web/logs").json()
    assert lines[-1]["message"] == "a line for the page" and lines[-1]["level"] == "WARNING"
    assert client.get(f"/api/v1/web/logs?after={lines[-1]['n']}").json() == []


def test_stop_stops_primitives_and_moves_then_lets_go_or_holds(
    client: httpx.Client, served: Served
) -> None:
    robot = served.robot
    robot.compliant = False
    client.post("/api/v1/primitives/sinus/start").raise_for_status()
    answer = client.post("/api/v1/web/stop", json={"then": "compliant"}).json()
    assert answer["primitives"] == ["sinus"] and answer["then"] == "compliant"
    assert not robot.sinus.is_alive() and robot.compliant is True
    client.post("/api/v1/primitives/sinus/start").raise_for_status()
    client.post("/api/v1/web/stop", json={"then": "hold"}).raise_for_status()
    assert not robot.sinus.is_alive()
    assert all(not m.compliant for m in robot.motors)
    assert "Stop from the web page" in client.get("/api/v1/web/logs").json()[-1]["message"]
    assert client.post("/api/v1/web/stop", json={"then": "run"}).status_code == 422
    robot.compliant = True


@pytest.fixture(scope="module")
def with_token(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder, token="s3cret")


def test_with_a_token_only_the_page_is_public(with_token: Served) -> None:
    with httpx.Client(base_url=with_token.url, timeout=http_timeout(10.0)) as http:
        assert http.get("/").status_code == 200
        assert http.get("/web/app.js").status_code == 200
        for path in ("/api/v1/web/about", "/api/v1/web/logs", "/routes", "/robot.json"):
            assert http.get(path).status_code == 401, path
        assert http.post("/api/v1/web/stop", json={}).status_code == 401
        headers = {"Authorization": "Bearer s3cret"}
        assert http.get("/api/v1/web/about", headers=headers).status_code == 200


def test_uptime_grows(client: httpx.Client) -> None:
    first = client.get("/api/v1/web/about").json()["uptime_s"]
    time.sleep(0.25)
    assert client.get("/api/v1/web/about").json()["uptime_s"] >= first
