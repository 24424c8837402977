"""A robot renamed from the page answers on Zenoh under its new name at once, and the change is
logged with who asked over Zenoh; `poppy fleet` takes `--zenoh-connect` as `poppy serve` does."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, ZenohSettings, serve
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.zenoh_wire import ZenohSettings as Settings
from tests.helpers.cli import run_poppy
from tests.helpers.fake_tools import FakeTools
from tests.helpers.waiting import eventually
from tests.helpers.zenoh_served import TOKEN, Served, fleet_timeout_s, free_endpoint

pytest.importorskip("zenoh")


def test_a_robot_renamed_over_zenoh_answers_its_new_key_and_the_log_names_the_peer(
    moves: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    fake = FakeTools(tmp_path, monkeypatch)
    endpoint = free_endpoint()
    spec = ServeSpec(
        http=Listen(port=0), zenoh=ZenohSettings(listen=(endpoint,)), name="jr-old", token=TOKEN
    )
    caplog.set_level(logging.WARNING, logger="poppy_core.server.settings")
    with from_profile("ergo-jr", sim=True) as robot, serve(robot, spec) as servers:
        with Fleet(
            Settings(connect=(endpoint,)), token=TOKEN, timeout_s=fleet_timeout_s()
        ) as fleet:
            assert fleet.wait_for(["jr-old"]) == ["jr-old"]
            (renamed,) = fleet.command(
                ["jr-old"], "PUT", "/api/v1/settings/name", {"name": "jr-new"}, together=False
            )
            assert renamed.status == 200, renamed.message
            assert eventually(lambda: fleet.names() == ["jr-new"], timeout_s=10)
            (motors,) = fleet.command(["jr-new"], "GET", "/api/v1/motors", together=False)
            assert motors.status == 200
            (old,) = fleet.command(["jr-old"], "GET", "/api/v1/motors", together=False)
            assert not old.ok and "no robot of that name" in old.message
            assert fleet.describe(["jr-new"])["jr-new"]["name"] == "jr-new"
        assert servers.zenoh is not None and servers.zenoh.name == "jr-new"
    assert fake.changes() == [["hostnamectl", "set-hostname", "jr-new"]]
    (line,) = [r.getMessage() for r in caplog.records if "renamed the robot" in r.getMessage()]
    assert line.startswith("settings: zenoh:") and f"(zenoh {fleet.session.zid()})" in line


def test_fleet_takes_zenoh_connect_as_serve_says_it(moves: Path) -> None:
    served = Served("jr-z")
    try:
        result = run_poppy("fleet", "list", "--json", "--zenoh-connect", served.endpoint)
        assert result.code == 0, result.stderr
        assert [row["name"] for row in result.json()] == ["jr-z"]
    finally:
        served.close()
