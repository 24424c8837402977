"""The page's Sensors panel in Debian's chromium (Playwright): every sensor but the cameras, its
kind, health and live values; a failed read shows the sensor's reason; none, no panel."""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

import pytest

from poppy_core import from_config
from poppy_core.errors import SensorError
from poppy_core.robot import RobotConfig, load_profile
from tests.helpers.chromium import launched, needs_chromium, new_tab
from tests.helpers.server import Served, serve_robot
from tests.helpers.waiting import eventually

pytestmark = needs_chromium

WAIT_MS = 60_000
LIVE = "() => window.poppy && window.poppy.ready && window.poppy.stats.frames > 0"
IMU = {"type": "RazorIMU", "port": "/dev/ttyUSB9"}  # a level, still IMU under sim=True
BLOB = {"type": "BlobDetector", "cameras": ["camera"], "filters": {"R": [150, 255]}}


def ergo_jr(sensors: dict[str, Any]) -> RobotConfig:
    """The Ergo Jr's config with ``sensors`` in place of its own."""
    data = load_profile("ergo-jr").to_pypot_dict()
    data["sensors"] = sensors
    return RobotConfig.from_dict(data, source="robot.json")


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    yield from launched()


@pytest.fixture(scope="module")
def served(moves_folder: str) -> Iterator[Served]:
    """A virtual Ergo Jr with its camera, an IMU and a blob detector."""
    camera = load_profile("ergo-jr").to_pypot_dict()["sensors"]["camera"]
    robot = from_config(ergo_jr({"camera": camera, "imu": IMU, "blob": BLOB}), sim=True)
    yield from serve_robot(robot)


@pytest.fixture
def page(browser: Any, served: Served) -> Iterator[Any]:
    context, opened = new_tab(browser, WAIT_MS)
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


def value(page: Any, sensor: str, register: str) -> str:
    found = page.locator(f"#sensor-{sensor} dd[data-register={register}]")
    return str(found.inner_text()).replace("\u00a0", " ") if found.count() else ""


def test_the_panel_lists_every_sensor_but_the_camera_with_its_values(page: Any) -> None:
    assert eventually(lambda: bool(value(page, "imu", "orientation")), 30.0), "the IMU values"
    shown = page.eval_on_selector_all("#sensor-list .sensor", "cards => cards.map(c => c.id)")
    assert shown == ["sensor-imu", "sensor-blob"]  # config order, no camera
    assert page.is_visible("#sensor-panel")
    assert "StillIMU" in page.inner_text("#sensor-imu h3")  # the RazorIMU, simulated
    assert "BlobDetector" in page.inner_text("#sensor-blob h3")
    assert value(page, "imu", "orientation") == "yaw 0.0° · pitch 0.0° · roll 0.0°"
    assert "z 9.81 m/s²" in value(page, "imu", "acceleration")
    assert eventually(lambda: value(page, "blob", "blobs") == "0 blobs", 30.0)
    health = page.locator("#sensor-imu .sensor-health")
    # "ok · idle" until the health poll sees the IMU run (its values were read: it runs)
    assert eventually(lambda: re.fullmatch(r"ok · \d+ Hz", health.inner_text()) is not None, 30.0)


def test_a_failed_read_shows_the_reason_and_the_rest_goes_on(
    page: Any, served: Served, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert eventually(lambda: bool(value(page, "blob", "blobs")), 30.0)
    imu = served.robot.sensor("imu")

    def unplugged(register: str) -> Any:
        raise SensorError("/dev/ttyUSB9 went away: plug the IMU back in", sensor="imu")

    monkeypatch.setattr(imu, "read", unplugged)
    error = page.locator("#sensor-imu .sensor-error")
    assert eventually(lambda: error.is_visible(), 30.0), "the reason shown"
    assert "/dev/ttyUSB9 went away: plug the IMU back in" in error.inner_text()
    assert value(page, "blob", "blobs") == "0 blobs"  # the other sensor still read
    monkeypatch.undo()
    assert eventually(lambda: not error.is_visible(), 30.0), "the reason gone once it reads"
    assert value(page, "imu", "orientation").startswith("yaw 0.0°")


def test_a_phone_shows_the_panel_within_its_width(browser: Any, served: Served) -> None:
    context = browser.new_context(viewport={"width": 390, "height": 844}, is_mobile=True)
    phone = context.new_page()
    phone.set_default_timeout(WAIT_MS)
    try:
        phone.goto(served.url + "/")
        phone.wait_for_function(LIVE)
        assert eventually(lambda: bool(value(phone, "imu", "acceleration")), 30.0)
        width = phone.evaluate("document.documentElement.scrollWidth")
        assert width <= 390, f"the page is {width} px wide on a 390 px phone"
        panel = phone.locator("#sensor-panel").bounding_box()
        assert panel is not None and panel["x"] >= 0 and panel["x"] + panel["width"] <= 390
    finally:
        context.close()


def test_a_robot_with_only_a_camera_shows_no_panel(browser: Any, moves_folder: str) -> None:
    camera = load_profile("ergo-jr").to_pypot_dict()["sensors"]["camera"]
    for served in serve_robot(from_config(ergo_jr({"camera": camera}), sim=True)):
        context, page = new_tab(browser, WAIT_MS)
        try:
            page.goto(served.url + "/")
            page.wait_for_function(LIVE)
            assert page.is_hidden("#sensor-panel")
            assert page.locator("#sensor-list .sensor").count() == 0
            assert page.is_visible("#camera")  # the camera keeps its panel
        finally:
            context.close()
