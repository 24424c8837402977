"""The page's episode player in a real browser (Debian's chromium, WebGL by its software
renderer): an episode of a dataset recorded here (a synthetic camera, its video packed after
another episode's as LeRobot packs them) plays in the 3D view, the video and the plot: the
view's joints follow the state at the cursor, the video plays what poppy encodes (AV1 where
PyAV has it) inside the episode's span and advances, the plot is drawn, and the robot is not
moved."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pyarrow")
pytest.importorskip("av")

from poppy_core import from_profile
from poppy_core.dataset.video import H264
from tests.helpers.chromium import CHROMIUM, needs_chromium, new_tab, playwright_api
from tests.helpers.datasets import EPISODES, FPS, MOTORS, state, write_dataset
from tests.helpers.server import Served, serve_robot

pytestmark = needs_chromium

WAIT_S = 60.0
WEBGL_ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
OPENED = (
    "() => window.poppy && window.poppy.datasets && window.poppy.datasets.episode"
    " && window.poppy.view && window.poppy.view.episode"
)
# pixels of the plot in the state's colour (#2563eb) and the action's (#f97316)
PLOT_INK = """() => {
  const canvas = document.querySelector('#datasets canvas.episode-plot');
  const { data } = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height);
  let state = 0, action = 0;
  for (let i = 0; i < data.length; i += 4) {
    const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
    if (b > 180 && r < 160 && b - r > 80) state += 1;
    if (r > 200 && b < 140 && r - b > 100 && g > 80) action += 1;
  }
  return [state, action];
}"""


@pytest.fixture(scope="module")
def home(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    folder = tmp_path_factory.mktemp("lerobot")
    write_dataset(folder / "me" / "wave")  # AV1 where PyAV encodes it
    write_dataset(folder / "me" / "wave264", codec=H264)  # the writer's fallback
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("HF_LEROBOT_HOME", str(folder))
        yield folder


@pytest.fixture(scope="module")
def served(home: Path) -> Iterator[Served]:
    yield from serve_robot(from_profile("ergo-jr", sim=True))


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with playwright_api.sync_playwright() as driver:
        launched = driver.chromium.launch(executable_path=CHROMIUM, args=WEBGL_ARGS)
        yield launched
        launched.close()


def wait(page: Any, condition: str, what: str) -> None:
    try:
        page.wait_for_function(condition)
    except playwright_api.TimeoutError:
        seen = page.evaluate(
            "() => JSON.stringify({d: window.poppy && window.poppy.datasets, "
            "v: window.poppy && window.poppy.view && window.poppy.view.episode, "
            "t: window.poppy.datasets.videoTimes && window.poppy.datasets.videoTimes(), "
            "e: window.poppy.datasets.videoErrors && window.poppy.datasets.videoErrors()})"
        )
        raise AssertionError(f"timed out waiting for {what}; the page: {seen}") from None


def drawn_degrees(page: Any) -> dict[str, float]:
    return page.evaluate("() => window.poppy.view.degrees()")


@pytest.mark.parametrize("dataset", ["me/wave", "me/wave264"])
def test_an_episode_plays_in_the_3d_view_the_video_and_the_plot(
    browser: Any, served: Served, home: Path, dataset: str
) -> None:
    errors: list[str] = []
    _, page = new_tab(browser, WAIT_S * 1000)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.on("console", lambda m: errors.append(m.text) if "Security Policy" in m.text else None)
    start = {m.name: m.present_position for m in served.robot.motors}
    sent: list[str] = []  # every request that could change the robot (none: the player reads)
    page.on("request", lambda r: sent.append(f"{r.method} {r.url}") if r.method != "GET" else None)
    page.goto(served.url + f"/#dataset={dataset}&episode=1")
    wait(page, OPENED, "the episode to open in the 3D view")
    frames = EPISODES[1][0]
    before = EPISODES[0][0] / FPS  # the episode's span in the packed file
    span = (before, before + frames / FPS)
    assert page.evaluate("() => window.poppy.datasets.episode.frames") == frames

    # the plot: both curves drawn, the cursor drawn at each frame shown
    wait(page, "() => window.poppy.datasets.plotDraws > 0", "the plot")
    ink_state, ink_action = page.evaluate(PLOT_INK)
    assert ink_state > 100 and ink_action > 100, (ink_state, ink_action)

    # the keys step frames; the view's joints are the state at the cursor
    page.focus("#datasets .episode-player")
    for _ in range(12):
        page.keyboard.press("ArrowRight")
    wait(page, "() => window.poppy.datasets.frame === 12", "frame 12")
    page.keyboard.press("ArrowLeft")
    wait(page, "() => window.poppy.datasets.frame === 11", "frame 11")
    degrees = drawn_degrees(page)
    for name, value in zip(MOTORS, state(11), strict=True):
        assert degrees[name] == pytest.approx(value, abs=0.05), (name, degrees)
    assert page.evaluate("() => window.poppy.view.ghost") is True  # the action, as the ghost

    # the video: decoded (no media error), seeked inside the episode's span at frame 11
    wait(
        page,
        f"() => window.poppy.datasets.videoTimes()[0] > {before + 1.0}"
        f" && window.poppy.datasets.videoTimes()[0] < {before + 1.2}",
        "the video at frame 11",
    )
    assert page.evaluate("() => window.poppy.datasets.videoErrors()") == [None]
    wait(
        page,
        "() => document.querySelector('#datasets video').readyState >= 2",
        "a decoded picture",
    )

    # play: the video advances inside the span and leads the frames; it stops at the end
    seen = page.evaluate("() => window.poppy.datasets.videoTimes()[0]")
    page.click("#datasets .episode-player button:text-is('play')")
    wait(
        page,
        f"() => window.poppy.datasets.videoTimes()[0] > {seen + 0.3}"
        " && window.poppy.datasets.frame > 13",
        "the video to advance",
    )
    assert page.evaluate("() => window.poppy.datasets.ticks.video") > 0  # the video led
    later = page.evaluate("() => window.poppy.datasets.videoTimes()[0]")
    assert span[0] <= later <= span[1], (later, span)
    wait(
        page,
        f"() => !window.poppy.datasets.playing && window.poppy.datasets.frame === {frames - 1}",
        "the end of the episode",
    )
    last = page.evaluate("() => window.poppy.datasets.videoTimes()[0]")
    assert span[0] <= last <= span[1], (last, span)
    degrees = drawn_degrees(page)
    assert degrees["m1"] == pytest.approx(state(frames - 1)[0], abs=0.05)

    # the robot itself was never moved; back to it, the view follows it again
    for motor in served.robot.motors:
        assert abs(motor.present_position - start[motor.name]) < 1.0, motor.name
    assert not sent, sent
    page.click("#datasets button:text('back to the live robot')")
    wait(page, "() => !window.poppy.view.episode", "the live view")
    assert abs(drawn_degrees(page)["m1"] - served.robot.motor("m1").present_position) < 1.0
    page.context.close()
    assert not errors, errors


def test_the_videos_played_are_what_poppy_writes(home: Path) -> None:
    """me/wave: AV1 where this PyAV encodes it (libsvtav1), else H.264; me/wave264: H.264."""
    import av

    from poppy_core.dataset.video import AV1, pick_codec

    def codec(name: str) -> str:
        path = home / name / "videos/observation.images.top/chunk-000/file-000.mp4"
        with av.open(str(path)) as container:
            return str(container.streams.video[0].codec_context.name)

    av1 = codec("me/wave")
    assert ("av1" in av1 or "dav1d" in av1) == (pick_codec() == AV1), av1
    assert codec("me/wave264") == "h264"


def test_with_a_token_the_video_is_read_with_it_and_no_url_holds_it(
    browser: Any, home: Path
) -> None:
    token = "player-token-7"
    urls: list[str] = []
    for served in serve_robot(from_profile("ergo-jr", sim=True), token=token):
        context = browser.new_context(viewport={"width": 1280, "height": 900})
        context.add_init_script(f"localStorage.setItem('poppy-token', '{token}')")
        page = context.new_page()
        page.set_default_timeout(WAIT_S * 1000)
        page.on("request", lambda request: urls.append(request.url))
        page.goto(served.url + "/#dataset=me/wave&episode=1")
        wait(page, OPENED, "the episode to open")
        source = page.evaluate("() => document.querySelector('#datasets video').src")
        assert source.startswith("blob:"), source
        wait(
            page,
            "() => document.querySelector('#datasets video').readyState >= 2",
            "a decoded picture from the blob",
        )
        assert page.evaluate("() => window.poppy.datasets.videoErrors()") == [None]
        assert any("/video/top" in url for url in urls), urls
        assert not [url for url in urls if token in url], urls
        context.close()
