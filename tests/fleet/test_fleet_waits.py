"""`poppy fleet stop` and `fleet status` wait for the robots' answers as they arrive, for the
fleet's measured time, not a fixed one: a loaded robot that answers after the fleet's 2 s is
still waited for (``Fleet.answer_limit_s``: its measured round trip times 3), and `status`
prints once each robot's health came, not after a fixed 1.2 s sleep.

The loaded robot is one whose Zenoh answers (its ``api`` and ``description``) come
``DELAY_S`` late, through a router process as users deploy it.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_core.remote.zenoh_fleet import DEFAULT_TIMEOUT_S
from poppy_core.server.zenoh import robot_node
from tests.helpers.cli import run_poppy
from tests.helpers.zenoh_router import Router
from tests.helpers.zenoh_served import TOKEN, Served

pytest.importorskip("zenoh")

DELAY_S = DEFAULT_TIMEOUT_S + 0.8
"""How late the loaded robot answers: past the fleet's fixed timeout."""


def _late(answer: Callable[[Any, Any], None]) -> Callable[[Any, Any], None]:
    def late(node: Any, query: Any) -> None:
        time.sleep(DELAY_S)
        answer(node, query)

    return late


@pytest.fixture
def loaded(moves: Path, router: Router, monkeypatch: pytest.MonkeyPatch) -> Iterator[Served]:
    node = robot_node.ZenohRobotServer
    monkeypatch.setattr(node, "_on_api", _late(node._on_api))
    monkeypatch.setattr(node, "_on_description", _late(node._on_description))
    served = Served("jr-slow", router=router.endpoint)
    try:
        yield served
    finally:
        served.close()


def test_fleet_stop_waits_for_a_loaded_robots_answer(router: Router, loaded: Served) -> None:
    service = loaded.servers.service
    loaded.robot.compliant = False
    service.control_primitive("sinus", "start")
    assert "sinus" in service.running_primitives()
    connect = ["--connect", router.endpoint, "--token", TOKEN]
    result = run_poppy("fleet", "stop", "--robots", "jr-slow", "--json", *connect)
    assert result.code == 0, (result.stdout, result.stderr)
    [outcome] = result.json()
    assert outcome["name"] == "jr-slow" and outcome["ok"] is True and outcome["status"] == 200
    assert service.running_primitives() == []


@pytest.fixture
def rare_health(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(robot_node, "HEALTH_PERIOD_S", 2.5)


def test_fleet_status_prints_once_each_robots_health_came(
    moves: Path, router: Router, rare_health: None
) -> None:
    served = Served("jr-rare", router=router.endpoint)
    try:
        result = run_poppy("fleet", "status", "--connect", router.endpoint)
    finally:
        served.close()
    assert result.code == 0, result.stderr
    [line] = [line for line in result.stdout.splitlines() if "jr-rare" in line]
    assert " ok " in f" {line} " and "m6:" in line, line
