"""The settings panel of the page in Debian's chromium (Playwright), against recording fakes of
the OS's tools: a rename from the page runs hostnamectl with the token; without NetworkManager
the panel is read-only and says why."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.chromium import launched, needs_chromium
from tests.helpers.fake_tools import FakeTools
from tests.helpers.server import Served, serve
from tests.helpers.waiting import eventually

pytestmark = needs_chromium

TOKEN = "s3cret"
WAIT_MS = 60_000


@pytest.fixture(scope="module")
def with_token(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder, token=TOKEN)


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    yield from launched()


@pytest.fixture
def fake(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> FakeTools:
    return FakeTools(tmp_path, monkeypatch)


@pytest.fixture(scope="module")
def tab(browser: Any) -> Iterator[Any]:
    """The module's tab, the token put in its storage before each page's scripts run (a new
    context costs the browser about three times what loading the page again in this one does)."""
    context = browser.new_context()
    context.add_init_script(f"localStorage.setItem('poppy-token', '{TOKEN}')")
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    yield page
    context.close()


def _settings_page(tab: Any, served: Served) -> Any:
    """The home page loaded afresh in the module's tab, its settings panel open."""
    page = tab
    page.goto(served.url + "/")
    page.wait_for_function("() => window.poppy && window.poppy.ready")
    page.click("#settings-open")
    page.wait_for_selector("#settings-version")
    return page


def test_renaming_from_the_page_runs_hostnamectl(
    tab: Any, with_token: Served, fake: FakeTools
) -> None:
    page = _settings_page(tab, with_token)
    try:
        assert page.inner_text("#settings-version").startswith("poppy ")
        assert page.is_hidden("#settings-reason")
        page.fill("#settings-name", "ergo-7")
        page.click("#settings-rename")
        assert eventually(lambda: fake.changes() != [], 30.0)
        assert fake.changes() == [["hostnamectl", "set-hostname", "ergo-7"]]
        page.wait_for_function(
            "() => document.getElementById('message').textContent.includes('ergo-7.local')"
        )
    finally:
        page.goto("about:blank")  # the page's stream and polls end with the test


def test_without_networkmanager_the_panel_is_read_only_and_says_why(
    tab: Any, with_token: Served, fake: FakeTools, monkeypatch: pytest.MonkeyPatch
) -> None:
    fake.alone(monkeypatch)
    fake.remove("nmcli")
    page = _settings_page(tab, with_token)
    try:
        assert "nmcli not found" in page.inner_text("#settings-reason")
        assert page.is_disabled("#settings-rename") and page.is_disabled("#settings-name")
    finally:
        page.goto("about:blank")  # the page's stream and polls end with the test
    assert fake.changes() == []


def test_snap_and_the_token_from_the_page_write_the_files_and_restart_the_service(
    tab: Any,
    with_token: Served,
    fake: FakeTools,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from poppy_core.server import serve_options
    from poppy_core.server.settings_os import SystemTools

    folder = tmp_path / "service"
    serve_options.write_options(folder / "serve.json", serve_options.ServeOptions())
    serve_options.write_token(folder / "token", "an-old-token-1")
    settings = with_token.app.state.settings
    monkeypatch.setattr(settings.served, "settings_file", folder / "serve.json")
    monkeypatch.setattr(settings.served, "token_file", folder / "token")
    monkeypatch.setattr(settings, "system", SystemTools(cgroup="0::/system.slice/poppy.service"))
    restart = ["systemctl", "restart", "--no-block", "poppy.service"]
    page = _settings_page(tab, with_token)
    try:
        # ZMQ has no token: a robot requiring one does not turn it on from its page, which says so
        assert page.is_disabled("#settings-zmq")
        assert "ZMQ API has no token" in page.inner_text("#settings")
        page.check("#settings-snap")
        assert eventually(lambda: fake.changes() == [restart], 30.0)
        assert serve_options.read_options(folder / "serve.json").snap
        page.wait_for_function(
            "() => document.getElementById('message').textContent.includes('Reconnected')"
        )
        page.fill("#settings-new-token", "a-new-token-42")
        page.click("#settings-change-token")
        assert eventually(lambda: fake.changes() == [restart, restart], 30.0)
        assert serve_options.read_token(folder / "token") == "a-new-token-42"
        # the page sends the new token once the service is back
        page.wait_for_function("() => localStorage.getItem('poppy-token') === 'a-new-token-42'")
    finally:
        page.goto("about:blank")  # the page's stream and polls end with the test
