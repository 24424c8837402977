"""The page's 3D view for ``python -m bench web``: first paint and frame rate, Ergo Jr and Humanoid.

Each creature is served in its own process (``poppy serve --http --sim``) and its page opened in
Debian's headless chromium with its software WebGL (SwiftShader). First paint: the page's first
contentful paint and the 3D view's first frame, from navigation start (``performance``, in the
page; fresh browser contexts after a cold one). Frame rate: the view asked to draw every
animation frame (``window.poppy.view.continuous``) while the robot moves, frames counted over a
window; the page otherwise draws only when a frame or the mouse changed something.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any

from bench.registry import Table

GOAL_FPS = {"ergo-jr": 30.0, "humanoid": 20.0}
"""Frames per second the view must keep while drawing continuously."""
DRAWN = "() => window.poppy && window.poppy.view && window.poppy.view.firstDrawAt != null"
FCP = (
    "() => (performance.getEntriesByName('first-contentful-paint')[0] || {startTime: null})"
    ".startTime"
)
MOVING = {"ergo-jr": "sinus", "humanoid": None}
VIEWPORT = {"width": 1280, "height": 900}


def _paint(chrome: Any, url: str) -> tuple[float, float]:
    context = chrome.new_context(viewport=VIEWPORT)
    page = context.new_page()
    page.goto(url)
    page.wait_for_function(DRAWN, timeout=60_000)
    first = (float(page.evaluate(FCP)), float(page.evaluate("window.poppy.view.firstDrawAt")))
    context.close()
    return first


def _fps(chrome: Any, url: str, seconds: float) -> tuple[float, int, float, float]:
    context = chrome.new_context(viewport=VIEWPORT)
    page = context.new_page()
    page.goto(url)
    page.wait_for_function(DRAWN, timeout=60_000)
    meshes = int(page.evaluate("window.poppy.view.meshes"))
    page.evaluate("window.poppy.view.continuous = true")
    time.sleep(1.0)
    before, start = page.evaluate("window.poppy.view.frames"), time.monotonic()
    time.sleep(seconds)
    rate = (page.evaluate("window.poppy.view.frames") - before) / (time.monotonic() - start)
    page.evaluate("window.poppy.view.empty = true")  # the same view drawing an empty scene
    before, start = page.evaluate("window.poppy.view.frames"), time.monotonic()
    time.sleep(seconds)
    empty = (page.evaluate("window.poppy.view.frames") - before) / (time.monotonic() - start)
    page.click("#view3d h2 button")  # hide: the same page, the view drawing nothing
    ceiling = float(page.evaluate(PAGE_RATE.replace("SECONDS", str(seconds))))
    context.close()
    return rate, meshes, empty, ceiling


PAGE_RATE = """() => new Promise((done) => {
  let frames = 0;
  const start = performance.now();
  function tick() {
    frames += 1;
    if (performance.now() - start < SECONDS * 1000) requestAnimationFrame(tick);
    else done(frames / ((performance.now() - start) / 1000));
  }
  requestAnimationFrame(tick);
})"""
"""The page's own animation frame rate (its ceiling): frames counted with the view hidden."""


def measure_view(
    served: Callable[[str], AbstractContextManager[tuple[str, int]]],
    browser: Callable[[], AbstractContextManager[Any]],
    repeat: int,
    seconds: float,
) -> dict[str, Any]:
    """First paints and frame rate of the 3D view, per creature."""
    import httpx

    figures: dict[str, Any] = {}
    for profile in GOAL_FPS:
        with (
            served(profile) as (url, _pid),
            browser() as chrome,
            httpx.Client(base_url=url, timeout=10.0) as http,
        ):
            http.put("/api/v1/robot/compliant", json={"compliant": False})
            primitive = MOVING[profile]
            if primitive:
                http.post(f"/api/v1/primitives/{primitive}/start")
            paints = [_paint(chrome, url + "/") for _ in range(repeat + 1)]
            rate, meshes, empty, ceiling = _fps(chrome, url + "/", seconds)
        figures[profile] = {
            "paints_ms": paints,
            "fps": rate,
            "meshes": meshes,
            "empty_fps": empty,
            "ceiling": ceiling,
        }
    return figures


def view_table(figures: dict[str, Any]) -> tuple[Table, bool]:
    """The 3D view's table and whether every goal was met."""
    rows, met = [], True
    for profile, raw in figures.items():
        warm = raw["paints_ms"][1:] or raw["paints_ms"]
        page = statistics.median(p[0] for p in warm)
        view = statistics.median(p[1] for p in warm)
        ok = raw["fps"] >= GOAL_FPS[profile]
        met = met and ok
        name = f"{profile} ({raw['meshes']} meshes)"
        rows.append([name, "page's first paint", f"{page:.0f} ms", "", ""])
        rows.append([name, "3D view's first frame", f"{view:.0f} ms", "", ""])
        rows.append(
            [
                name,
                "frames per second, drawing continuously",
                f"{raw['fps']:.1f}",
                f"≥ {GOAL_FPS[profile]:.0f}",
                "yes" if ok else "**no**",
            ]
        )
        rows.append(
            [
                name,
                "the same view drawing an empty scene (a WebGL frame's own cost)",
                f"{raw['empty_fps']:.1f}",
                "",
                "",
            ]
        )
        rows.append(
            [
                name,
                "the page's own frame rate, the view hidden (its ceiling)",
                f"{raw['ceiling']:.1f}",
                "",
                "",
            ]
        )
    table = Table("3D view", ["robot", "measure", "value", "goal", "met"], rows)
    return table, met


def screenshots(
    served: Callable[[str], AbstractContextManager[tuple[str, int]]],
    browser: Callable[[], AbstractContextManager[Any]],
    folder: str,
) -> list[str]:
    """The 3D view's panel of a served Ergo Jr and Humanoid, an arm raised (PNG files)."""
    import httpx

    poses = {"ergo-jr": {"m1": 30.0, "m2": -20.0, "m3": 30.0}, "humanoid": {"l_shoulder_y": -70.0}}
    written = []
    for profile, pose in poses.items():
        with (
            served(profile) as (url, _pid),
            browser() as chrome,
            httpx.Client(base_url=url, timeout=10.0) as http,
        ):
            http.put("/api/v1/robot/compliant", json={"compliant": False})
            body = {"positions": pose, "duration_s": 1.0, "wait": True}
            http.post("/api/v1/gotos", json=body)
            context = chrome.new_context(viewport=VIEWPORT, device_scale_factor=1)
            page = context.new_page()
            page.goto(url + "/")
            page.wait_for_function(DRAWN, timeout=60_000)
            time.sleep(1.0)
            path = f"{folder}/web-3d-{profile}.png"
            page.locator("#view3d").screenshot(path=path)
            written.append(path)
            context.close()
    return written


def main() -> None:
    """``python -m bench.web_view_bench [FOLDER]``: the 3D view's figures for docs/web.md."""
    import sys

    from bench.web_bench import browser, served

    for path in screenshots(served, browser, sys.argv[1] if len(sys.argv) > 1 else "docs/img"):
        print(path)


if __name__ == "__main__":
    main()
