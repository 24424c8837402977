"""The page's "Record a dataset" panel in chromium: the form filled, lerobot-record's keys pressed
on the panel (← records the episode again, → ends it and then the reset, Esc stops), the live
line following, and the dataset on the robot holding the episodes kept."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pyarrow.parquet as pq
import pytest

from poppy_core import from_profile
from tests.helpers.chromium import new_tab
from tests.helpers.server import Served, serve_robot
from tests.helpers.waiting import http_timeout
from tests.server.test_web_page import (  # noqa: F401 (browser is a fixture)
    LIVE,
    WAIT_S,
    browser,
    eventually,
)

pytestmark = pytest.mark.slow


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "lerobot"))
    return tmp_path / "lerobot"


@pytest.fixture
def served(home: Path, moves_folder: str) -> Iterator[Served]:
    yield from serve_robot(from_profile("ergo-jr", sim=True))


def test_the_panel_records_with_the_keys(browser: Any, served: Served, home: Path) -> None:  # noqa: F811
    context, tab = new_tab(browser, WAIT_S * 1000)
    errors: list[str] = []
    tab.on("pageerror", lambda error: errors.append(str(error)))
    http = httpx.Client(base_url=served.url, timeout=http_timeout(10.0))

    def state() -> dict[str, Any]:
        found: dict[str, Any] = http.get("/api/v1/recording").json()
        return found

    try:
        tab.goto(served.url + "/")
        tab.wait_for_function(LIVE)
        eventually(lambda: tab.is_visible("#dataset-cameras input[value=camera]"), "the cameras")
        assert tab.inner_text("#dataset-live") == "No recording yet."
        tab.fill("#dataset-form input[name=repo_id]", "class/page")
        tab.fill("#dataset-form input[name=task]", "wave from the page")
        tab.select_option("#dataset-form select[name=source]", "by_hand")
        tab.fill("#dataset-form input[name=episodes]", "3")
        tab.fill("#dataset-form input[name=episode_s]", "120")
        tab.fill("#dataset-form input[name=reset_s]", "120")
        tab.fill("#dataset-form input[name=fps]", "10")
        tab.uncheck("#dataset-cameras input[value=camera]")
        tab.click("#dataset-start")
        eventually(lambda: state()["active"] and state()["frames"] >= 3, "episode 1 recording")
        eventually(lambda: "episode 1/3" in tab.inner_text("#dataset-live"), "the live line")
        eventually(
            lambda: tab.evaluate(
                "() => document.getElementById('dataset-record').contains(document.activeElement)"
            ),
            "the panel focused",
        )
        tab.keyboard.press("ArrowLeft")  # record episode 1 again, after a reset
        eventually(lambda: state()["phase"] == "resetting", "the reset after the take dropped")
        assert state()["episode"] == 1 and state()["saved"] == []
        tab.keyboard.press("ArrowRight")  # the reset skipped
        eventually(lambda: state()["rerecorded"] == 1 and state()["frames"] >= 3, "a new take")
        tab.keyboard.press("ArrowRight")  # episode 1 saved, the reset begins
        eventually(lambda: state()["phase"] == "resetting", "the reset")
        eventually(lambda: "reset before episode 2/3" in tab.inner_text("#dataset-live"), "reset")
        tab.keyboard.press("ArrowRight")  # the reset skipped
        eventually(lambda: state()["episode"] == 2 and state()["frames"] >= 3, "episode 2")
        tab.keyboard.press("Escape")  # stop: episode 2 saved
        eventually(lambda: state()["phase"] == "done", "the recording's end")
        ended = state()
        assert [e["episode"] for e in ended["saved"]] == [0, 1] and ended["rerecorded"] == 1
        eventually(lambda: tab.inner_text("#dataset-live").startswith("done: 2 episode(s)"), "done")
        # Esc on the panel stopped the recording, not every motion (the page's Stop dialog)
        assert not tab.evaluate("() => document.getElementById('stop-dialog').open")
        assert tab.is_enabled("#dataset-start") and not tab.is_enabled("#dataset-stop")
        # the same name again, without "Add to it": the server's one line on the status line
        tab.click("#dataset-start")
        eventually(lambda: "already exists" in tab.inner_text("#message"), "the refusal")
        assert "error" in (tab.get_attribute("#message", "class") or "")
    finally:
        http.close()
        context.close()
    assert not errors, errors
    root = home / "class/page"
    info = json.loads((root / "meta/info.json").read_text())
    frames = sum(e["frames"] for e in ended["saved"])
    assert (info["total_episodes"], info["total_frames"]) == (2, frames)
    assert "observation.images.camera" not in info["features"]
    data = pq.read_table(root / "data/chunk-000/file-000.parquet").to_pydict()
    assert data["frame_index"][: ended["saved"][0]["frames"]] == list(
        range(ended["saved"][0]["frames"])
    )
