"""Browser test helpers: Debian's chromium driven by Playwright (skips without either)."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from typing import Any

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
"""Debian's chromium, or None."""

playwright_api = pytest.importorskip(
    "playwright.sync_api", reason="needs playwright (pip install -e '.[test]')"
)
"""``playwright.sync_api`` (importing this module skips the test module without it)."""

needs_chromium = pytest.mark.skipif(
    CHROMIUM is None, reason="needs Debian's chromium (apt-get install chromium)"
)
"""A test module's ``pytestmark`` where it drives the browser."""

HEADLESS_ARGS = ["--no-sandbox", "--disable-gpu"]


def launched(*args: str) -> Iterator[Any]:
    """A headless chromium (``HEADLESS_ARGS`` and ``args``) until the generator is closed."""
    with playwright_api.sync_playwright() as driver:
        browser = driver.chromium.launch(executable_path=CHROMIUM, args=[*HEADLESS_ARGS, *args])
        yield browser
        browser.close()


def new_tab(browser: Any, timeout_ms: float) -> tuple[Any, Any]:
    """A fresh context (a 1280x900 window) and its page, waiting up to ``timeout_ms``."""
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    tab = context.new_page()
    tab.set_default_timeout(timeout_ms)
    return context, tab
