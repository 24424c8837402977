"""The page's 3D view in a real browser: Debian's chromium (WebGL 2 by its software renderer).

The view draws the virtual robot from its URDF and meshes and moves with the state stream: the
canvas is not blank, its pixels change when a motor moves, and each chain's tip is drawn where
the server's kinematics put it (the motors' angles turn the URDF's joints as the chains read
them). Also the model's routes (URDF,
meshes, cache headers) and the line shown where the browser has no WebGL.
"""

from __future__ import annotations

import io
from collections.abc import Iterator
from typing import Any

import httpx
import numpy as np
import pytest

from poppy_core import from_profile
from tests.helpers.chromium import CHROMIUM, HEADLESS_ARGS, needs_chromium, new_tab, playwright_api
from tests.helpers.server import serve_robot
from tests.helpers.waiting import eventually, http_timeout
from tests.server.conftest import Served

Image = pytest.importorskip("PIL.Image", reason="needs pillow to read the screenshots")
pytestmark = needs_chromium

WAIT_S = 60.0
WEBGL_ARGS = [
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-gpu-compositing",
]
DRAWN = "() => window.poppy && window.poppy.view && window.poppy.view.frames > 0"


@pytest.fixture(scope="module")
def driver() -> Iterator[Any]:
    with playwright_api.sync_playwright() as running:
        yield running


@pytest.fixture(scope="module")
def browser(driver: Any) -> Iterator[Any]:
    launched = driver.chromium.launch(executable_path=CHROMIUM, args=WEBGL_ARGS)
    yield launched
    launched.close()


@pytest.fixture(scope="module")
def humanoid(moves_folder: str) -> Iterator[Served]:
    """A virtual Humanoid served on 127.0.0.1."""
    yield from serve_robot(from_profile("humanoid", sim=True))


@pytest.fixture(scope="module")
def tab(browser: Any) -> Iterator[tuple[Any, list[str]]]:
    """The module's tab and the errors its page reports (a new context costs the browser about
    three times what loading the page again in this one does)."""
    context, page = new_tab(browser, WAIT_S * 1000)
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.on(
        "console",
        lambda m: errors.append(m.text) if "Content Security Policy" in m.text else None,
    )
    yield page, errors
    context.close()


def open_view(tab: tuple[Any, list[str]], url: str) -> tuple[Any, list[str]]:
    """``url``'s home page loaded afresh in the module's tab, its view drawn; the page's errors
    from then on."""
    page, errors = tab
    errors.clear()
    page.goto(url + "/")
    page.wait_for_function(DRAWN)
    return page, errors


def wait(page: Any, condition: str, what: str) -> None:
    """Wait for a condition of the page, saying what was awaited if it never comes."""
    try:
        page.wait_for_function(condition)
    except playwright_api.TimeoutError:
        state = page.evaluate("() => JSON.stringify(window.poppy && window.poppy.view)")
        raise AssertionError(f"timed out waiting for {what}; the view: {state}") from None


def pixels(page: Any) -> np.ndarray:
    png = page.locator("#view3d canvas").screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def changed(before: np.ndarray, after: np.ndarray) -> int:
    """How many pixels differ clearly between two shots."""
    return int((np.abs(before - after).max(axis=2) > 24).sum())


def not_blank(shot: np.ndarray) -> bool:
    """More than a background: some pixels far from the most common colour."""
    flat = shot.reshape(-1, 3)
    colours, counts = np.unique(flat, axis=0, return_counts=True)
    background = colours[counts.argmax()]
    return int((np.abs(flat - background).max(axis=1) > 40).sum()) > 200


def move_and_compare(page: Any, robot: Any, motor: str, by_deg: float) -> int:
    before = pixels(page)
    assert not_blank(before), "the 3D canvas is blank"
    robot.compliant = False
    start = robot.motor(motor).present_position
    robot.goto_position({motor: start + by_deg}, 0.8, wait=True)
    assert eventually(
        lambda: abs(robot.motor(motor).present_position - (start + by_deg)) < 2, timeout_s=WAIT_S
    ), f"{motor} did not arrive"
    drawn = page.evaluate("() => window.poppy.view.updates")
    page.wait_for_function(f"() => window.poppy.view.updates > {drawn + 3}")  # frames after it
    page.wait_for_function("() => new Promise(r => requestAnimationFrame(() => r(true)))")
    after = pixels(page)
    robot.goto_position({motor: start}, 0.5, wait=True)
    robot.compliant = True
    return changed(before, after)


def tips_match_the_chains(page: Any, served: Served) -> None:
    """Each chain's tip as the view draws it is where the server's kinematics put it (1 mm)."""
    with httpx.Client(base_url=served.url, timeout=http_timeout(10.0)) as client:

        def apart() -> float:
            drawn = page.evaluate("() => window.poppy.view.tips()")
            assert drawn, "no chain tip drawn"
            told = {name: client.get(f"/api/v1/chains/{name}").json() for name in drawn}
            return max(
                float(np.linalg.norm(np.subtract(drawn[name], told[name]["position"])))
                for name in drawn
            )

        assert eventually(lambda: apart() < 0.001, timeout_s=WAIT_S), f"{apart() * 1000:.1f} mm"


def test_the_ergo_jr_is_drawn_and_m1_turning_30_degrees_changes_it(
    tab: tuple[Any, list[str]], served: Served
) -> None:
    page, errors = open_view(tab, served.url)
    assert move_and_compare(page, served.robot, "m1", 30.0) > 300
    served.robot.compliant = False
    served.robot.goto_position({"m1": 20.0, "m2": -30.0, "m3": 40.0, "m5": 25.0}, 0.5, wait=True)
    tips_match_the_chains(page, served)
    served.robot.goto_position({m.name: 0.0 for m in served.robot.motors}, 0.5, wait=True)
    served.robot.compliant = True
    page.goto("about:blank")  # the page's stream and polls end with the test
    assert not errors, errors


def test_the_humanoid_is_drawn_and_its_l_shoulder_y_moves_it(
    tab: tuple[Any, list[str]], humanoid: Served
) -> None:
    page, errors = open_view(tab, humanoid.url)
    assert move_and_compare(page, humanoid.robot, "l_shoulder_y", -60.0) > 150
    humanoid.robot.compliant = False
    humanoid.robot.goto_position({"l_shoulder_x": 40.0, "r_elbow_y": -50.0}, 0.5, wait=True)
    tips_match_the_chains(page, humanoid)
    page.goto("about:blank")  # the page's stream and polls end with the test
    assert not errors, errors


def test_a_goto_shows_its_goal_as_a_ghost_and_a_cartesian_goto_its_target(
    tab: tuple[Any, list[str]], served: Served
) -> None:
    page, errors = open_view(tab, served.url)
    robot = served.robot
    robot.compliant = False
    handle = robot.goto_position({"m2": 40.0}, 6.0)
    wait(page, "() => window.poppy.view.ghost === true", "the ghost during the goto")
    handle.wait()
    wait(page, "() => window.poppy.view.ghost === false", "no ghost once the goto is over")
    robot.goto_position({"m2": 0.0}, 0.5, wait=True)
    tip = robot.chain.position
    robot.chain.goto([tip[0], tip[1], tip[2] - 0.02], duration=6.0)
    wait(page, "() => window.poppy.view.targets === 1", "the target during the goto")
    robot.compliant = True
    page.goto("about:blank")  # the page's stream and polls end with the test
    assert not errors, errors


def test_what_a_running_marker_detector_sees_is_said_under_the_view(
    tab: tuple[Any, list[str]], served: Served, client: httpx.Client
) -> None:
    page, errors = open_view(tab, served.url)
    assert page.evaluate("() => window.poppy.view.seen") is None  # idle: not started by the view
    assert client.get("/api/v1/sensors/marker_detector").status_code == 200  # someone uses it
    wait(page, "() => window.poppy.view.seen === 'marker_detector sees no marker'", "the line")
    assert page.inner_text("#view3d .view-seen") == "marker_detector sees no marker"
    page.goto("about:blank")  # the page's stream and polls end with the test
    assert not errors, errors


def test_with_a_token_the_view_reads_the_model_and_meshes_with_it(
    browser: Any, moves_folder: str
) -> None:
    from tests.helpers.server import serve

    served = serve(moves_folder, token="s3cret-view")
    robot = next(served)
    try:
        context = browser.new_context(viewport={"width": 1280, "height": 900})
        page = context.new_page()
        urls: list[str] = []
        page.on("request", lambda request: urls.append(request.url))
        page.goto(robot.url + "/")
        page.wait_for_selector("#token-dialog[open]")
        page.fill("#token-input", "s3cret-view")
        page.click("#token-ok")
        wait(page, DRAWN, "the view drawn with the token")
        assert page.evaluate("() => window.poppy.view.missing") == []
        assert page.evaluate("() => window.poppy.view.meshes") == 7  # every mesh read
        assert not [u for u in urls if "s3cret" in u], "the token went into a URL"
        context.close()
    finally:
        served.close()


def test_without_webgl_the_page_says_so_in_one_line(driver: Any, served: Served) -> None:
    launched = driver.chromium.launch(
        executable_path=CHROMIUM, args=[*HEADLESS_ARGS, "--disable-webgl"]
    )
    try:
        page = launched.new_page()
        page.goto(served.url + "/")
        page.wait_for_function("() => window.poppy && window.poppy.view")
        assert "no WebGL" in page.inner_text("#view3d .view-note")
        assert page.locator("#view3d canvas").count() == 0
        assert page.is_visible("#motor-table")  # the rest of the page works
    finally:
        launched.close()


def test_the_goals_route_says_where_the_gotos_under_way_go(
    client: httpx.Client, served: Served
) -> None:
    robot = served.robot
    robot.compliant = False
    idle = {"goals": {}, "targets": {"chain": None}}  # once an earlier test's gotos are over
    assert eventually(lambda: client.get("/api/v1/model/goals").json() == idle, timeout_s=WAIT_S)
    handle = robot.goto_position({"m3": 25.0}, 5.0)
    live = client.get("/api/v1/model/goals").json()
    assert live["goals"] == {"m3": 25.0}
    handle.wait()
    assert client.get("/api/v1/model/goals").json()["goals"] == {}
    robot.goto_position({"m3": 0.0}, 0.3, wait=True)
    robot.compliant = True


def test_the_model_routes_hand_out_the_urdf_and_its_meshes(
    client: httpx.Client, served: Served
) -> None:
    model = client.get("/api/v1/model").json()
    assert model["urdf"] == "/api/v1/model/robot.urdf"
    assert set(model["joints"]) == {f"m{i}" for i in range(1, 7)}
    assert model["joints"]["m2"] == {"scale": -1.0, "offset_deg": 0.0}  # indirect
    assert model["chains"]["chain"]["tip_joint"] == "m6"
    served.robot.m3.offset = 4.0  # a calibration: the view turns the joints as the robot is now
    try:
        joint = client.get("/api/v1/model").json()["joints"]["m3"]
        assert joint == {"scale": -1.0, "offset_deg": 4.0}
    finally:
        served.robot.m3.offset = 0.0
    urdf = client.get(model["urdf"])
    assert urdf.status_code == 200 and b"<robot" in urdf.content
    assert "max-age" in urdf.headers["cache-control"]
    again = client.get(model["urdf"], headers={"If-None-Match": urdf.headers["etag"]})
    assert again.status_code == 304
    for name in model["mesh_files"][:1]:  # the meshes in the profile, when it has them
        mesh = client.get(model["meshes"] + name)
        assert mesh.status_code == 200 and mesh.headers["content-type"] == "model/stl"
    assert client.get(model["meshes"] + "..%2Fprofile.yaml").status_code == 404
    for bad in ("nothere.STL", "profile.yaml"):
        answer = client.get(model["meshes"] + bad)
        assert answer.status_code == 404, bad
        assert "mesh" in answer.json()["detail"]
