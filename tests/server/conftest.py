"""Fixtures: a virtual Ergo Jr served over real HTTP on 127.0.0.1 (uvicorn in a thread)."""

from __future__ import annotations

import os
from collections.abc import Iterator

import httpx
import pytest

from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout

__all__ = ["Served", "serve"]  # for tests of other helpers that still import them from here


@pytest.fixture(scope="module")
def moves_folder(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """An empty move library for the servers of one test module (POPPY_MOVES_DIR)."""
    folder = str(tmp_path_factory.mktemp("moves"))
    old = os.environ.get("POPPY_MOVES_DIR")
    os.environ["POPPY_MOVES_DIR"] = folder
    yield folder
    if old is None:
        os.environ.pop("POPPY_MOVES_DIR", None)
    else:
        os.environ["POPPY_MOVES_DIR"] = old


@pytest.fixture(scope="module")
def served(moves_folder: str) -> Iterator[Served]:
    """An Ergo Jr served without a token (one per test module)."""
    yield from serve(moves_folder)


@pytest.fixture
def client(served: Served) -> Iterator[httpx.Client]:
    """An HTTP client of ``served``. It lets an idle connection go after 2 s, before uvicorn's
    keep-alive timeout (5 s) closes it: a request sent on a connection the server is closing at
    that moment is reset (seen after a test's 5 s goto)."""
    limits = httpx.Limits(keepalive_expiry=2.0)
    with httpx.Client(base_url=served.url, timeout=http_timeout(10.0), limits=limits) as http:
        yield http
