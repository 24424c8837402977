"""Snap!/ZMQ on/off and the token from the page (issue 26.3): the change is written in the
service's files (``poppy serve --settings``/``--token-file``) and ``poppy.service`` restarts
through the adapter (``systemctl restart --no-block``, checked against the recording fake);
without the token, or on a server without these files, nothing is written nor run."""

from __future__ import annotations

import json
import logging
import stat
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from poppy_core.server import serve_options
from poppy_core.server.settings_os import SystemTools, unit_of
from tests.helpers.fake_tools import FakeTools
from tests.helpers.server import Served, serve
from tests.helpers.waiting import http_timeout

TOKEN = "s3cret-token-1"
BEARER = {"Authorization": f"Bearer {TOKEN}"}
UNDER_THE_SERVICE = "0::/system.slice/poppy.service\n"
RESTART = ["systemctl", "restart", "--no-block", "poppy.service"]


@pytest.fixture
def fake(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> FakeTools:
    return FakeTools(tmp_path, monkeypatch)


@pytest.fixture(scope="module")
def with_token(moves_folder: str) -> Iterator[Served]:
    yield from serve(moves_folder, token=TOKEN)


@pytest.fixture
def appliance(
    with_token: Served, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> Iterator[tuple[Served, Path]]:
    """The server as `poppy.service` runs it: its files in ``tmp_path/service``."""
    folder = tmp_path / "service"
    serve_options.write_options(folder / "serve.json", serve_options.ServeOptions(snap=True))
    serve_options.write_token(folder / "token", TOKEN)
    settings = with_token.app.state.settings
    monkeypatch.setattr(settings.served, "settings_file", folder / "serve.json")
    monkeypatch.setattr(settings.served, "token_file", folder / "token")
    monkeypatch.setattr(settings, "system", SystemTools(cgroup=UNDER_THE_SERVICE))
    yield with_token, folder


def options(folder: Path) -> dict[str, bool]:
    return dict(json.loads((folder / "serve.json").read_text()))


def test_the_adapter_restarts_the_service_without_waiting_for_it(fake: FakeTools) -> None:
    SystemTools(cgroup=UNDER_THE_SERVICE).restart_later("poppy.service")
    user = "0::/user.slice/user-1000.slice/user@1000.service/app.slice/poppy.service\n"
    tools = SystemTools(cgroup=user)
    assert tools.own_unit == "poppy.service" and tools.user_units
    tools.restart_later("poppy.service")
    assert fake.calls() == [RESTART, ["systemctl", "--user", *RESTART[1:]]]


def test_which_service_runs_this_process() -> None:
    assert unit_of(UNDER_THE_SERVICE) == "poppy.service"
    assert unit_of("0::/user.slice/user-1000.slice/session-3.scope\n") is None
    assert unit_of("0::/user.slice/user-1000.slice/user@1000.service/app.slice/x.scope") is None
    assert unit_of("0::/\n") is None


def test_snap_and_zmq_are_switched_in_the_file_and_the_service_restarts(
    fake: FakeTools, appliance: tuple[Served, Path], caplog: pytest.LogCaptureFixture
) -> None:
    served, folder = appliance
    serve_options.write_options(
        folder / "serve.json", serve_options.ServeOptions(snap=True, zmq=True)
    )
    caplog.set_level(logging.WARNING, logger="poppy_core.server.settings")
    with httpx.Client(base_url=served.url, headers=BEARER, timeout=http_timeout(30)) as http:
        shown = http.get("/api/v1/settings").json()
        assert shown["services"]["zmq"]["how"] == "settings" and shown["restarts"] is True
        assert shown["token_changeable"] is True
        answer = http.put("/api/v1/settings/services/zmq", json={"on": False})
        assert answer.status_code == 200, answer.text
        assert answer.json() == {"service": "zmq", "on": False, "restarting": True}
        assert options(folder) == {"snap": True, "zmq": False}
        assert http.put("/api/v1/settings/services/snap", json={"on": False}).is_success
        assert options(folder) == {"snap": False, "zmq": False}
        assert http.put("/api/v1/settings/services/snap", json={"on": True}).is_success
        assert options(folder) == {"snap": True, "zmq": False}
    assert fake.changes() == [RESTART, RESTART, RESTART]
    assert "turned zmq off" in caplog.text and "turned snap off" in caplog.text


def test_zmq_is_not_turned_on_from_the_page_of_a_robot_requiring_a_token(
    fake: FakeTools, appliance: tuple[Served, Path]
) -> None:
    # pypot's ZMQ API has no token: served on the robot's address, it would let anyone on the
    # network move a robot whose page and API require one. The page says why, and refuses.
    served, folder = appliance
    with httpx.Client(base_url=served.url, headers=BEARER, timeout=http_timeout(30)) as http:
        zmq = http.get("/api/v1/settings").json()["services"]["zmq"]
        assert "ZMQ API has no token" in zmq["reason"] and zmq["on"] is False
        answer = http.put("/api/v1/settings/services/zmq", json={"on": True})
    assert answer.status_code == 409, answer.text
    detail = answer.json()["detail"]
    assert "ZMQ API has no token" in detail and "\n" not in detail
    assert options(folder) == {"snap": True, "zmq": False}
    assert fake.changes() == []


def test_the_token_is_changed_in_its_file_readable_by_its_owner_only(
    fake: FakeTools, appliance: tuple[Served, Path], caplog: pytest.LogCaptureFixture
) -> None:
    served, folder = appliance
    caplog.set_level(logging.INFO)
    with httpx.Client(base_url=served.url, headers=BEARER, timeout=http_timeout(30)) as http:
        answer = http.put("/api/v1/settings/token", json={"token": "a-new-token-42"})
        assert answer.status_code == 200, answer.text
        assert answer.json() == {"changed": True, "restarting": True}
    assert serve_options.read_token(folder / "token") == "a-new-token-42"
    assert stat.S_IMODE((folder / "token").stat().st_mode) == 0o600
    assert fake.calls() == [RESTART]
    assert "changed the token" in caplog.text and "a-new-token-42" not in caplog.text


@pytest.mark.parametrize(
    ("path", "body", "headers", "status"),
    [
        ("/api/v1/settings/token", {"token": "a-new-token-42"}, {}, 401),
        ("/api/v1/settings/services/zmq", {"on": True}, {}, 401),
        ("/api/v1/settings/token", {"token": "short"}, BEARER, 422),
        ("/api/v1/settings/token", {"token": "has a space in it"}, BEARER, 422),
    ],
)
def test_a_change_without_the_token_or_a_bad_token_writes_and_runs_nothing(
    fake: FakeTools,
    appliance: tuple[Served, Path],
    path: str,
    body: object,
    headers: dict[str, str],
    status: int,
) -> None:
    served, folder = appliance
    with httpx.Client(base_url=served.url, timeout=http_timeout(30)) as http:
        answer = http.put(path, json=body, headers=headers)
    assert answer.status_code == status, answer.text
    assert options(folder) == {"snap": True, "zmq": False}
    assert serve_options.read_token(folder / "token") == TOKEN
    assert fake.calls() == []


def test_outside_the_service_the_change_applies_at_the_next_start(
    fake: FakeTools, appliance: tuple[Served, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    served, folder = appliance
    settings = served.app.state.settings
    monkeypatch.setattr(settings, "system", SystemTools(cgroup="0::/user.slice/session-2.scope"))
    with httpx.Client(base_url=served.url, headers=BEARER, timeout=http_timeout(30)) as http:
        assert http.get("/api/v1/settings").json()["restarts"] is False
        answer = http.put("/api/v1/settings/services/snap", json={"on": False})
        assert answer.json() == {"service": "snap", "on": False, "restarting": False}
    assert options(folder) == {"snap": False, "zmq": False}
    assert fake.changes() == []


def test_a_refused_restart_says_the_change_is_saved(
    fake: FakeTools, appliance: tuple[Served, Path]
) -> None:
    served, folder = appliance
    refused = "Failed to restart poppy.service: Interactive authentication required.\n"
    fake.canned[" ".join(RESTART)] = {"err": refused, "code": 1}
    fake.save()
    with httpx.Client(base_url=served.url, headers=BEARER, timeout=http_timeout(30)) as http:
        answer = http.put("/api/v1/settings/services/snap", json={"on": False})
    assert answer.status_code == 409
    detail = answer.json()["detail"]
    assert "saved in" in detail and "Interactive authentication required" in detail
    assert options(folder) == {"snap": False, "zmq": False}
    assert fake.calls() == [RESTART]


def test_a_server_without_the_files_says_how_to_get_them(
    fake: FakeTools, with_token: Served
) -> None:
    with httpx.Client(base_url=with_token.url, headers=BEARER, timeout=http_timeout(30)) as http:
        shown = http.get("/api/v1/settings").json()
        assert shown["services"]["snap"]["how"] == "serve --snap"
        assert shown["token_changeable"] is False
        snap = http.put("/api/v1/settings/services/snap", json={"on": True})
        assert snap.status_code == 409 and "without --settings" in snap.json()["detail"]
        token = http.put("/api/v1/settings/token", json={"token": "a-new-token-42"})
        assert token.status_code == 409 and "--token" in token.json()["detail"]
    assert fake.changes() == []


def test_the_files_rules(tmp_path: Path) -> None:
    assert serve_options.read_options(tmp_path / "missing.json") == serve_options.ServeOptions()
    bad = tmp_path / "bad.json"
    for text, says in [
        ("{", "is not JSON"),
        ("[]", "not a JSON object"),
        ('{"snap": "yes"}', "each true or false"),
        ('{"http": true}', "holds http"),
    ]:
        bad.write_text(text)
        with pytest.raises(serve_options.ConfigError, match=says):
            serve_options.read_options(bad)
    with pytest.raises(serve_options.ConfigError, match="does not exist"):
        serve_options.read_token(tmp_path / "none")
    (tmp_path / "empty").write_text("\n")
    with pytest.raises(serve_options.ConfigError, match="no valid token"):
        serve_options.read_token(tmp_path / "empty")
