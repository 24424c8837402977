"""A classroom's fleet through one Zenoh router process (`poppy fleet router`): the robots and
the teacher's commands connect only to it (explicit loopback endpoints, scouting off)."""

from __future__ import annotations

import os
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServeSpec, ZenohSettings, serve
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.robot import from_remote
from poppy_core.zenoh_wire import mode_of
from tests.helpers.cli import POPPY, command_env, run_poppy
from tests.helpers.processes import read_until, reap
from tests.helpers.waiting import eventually, http_timeout
from tests.helpers.zenoh_router import Router
from tests.helpers.zenoh_served import TOKEN, Served, fleet_timeout_s

pytest.importorskip("zenoh")


@pytest.fixture
def pair(moves: Path, router: Router) -> Iterator[tuple[Served, Served]]:
    a, b = Served("jr-a", router=router.endpoint), Served("jr-b", router=router.endpoint)
    try:
        yield a, b
    finally:
        a.close()
        b.close()


@pytest.fixture
def teacher(router: Router, pair: tuple[Served, Served]) -> Iterator[Fleet]:
    with Fleet(
        ZenohSettings(connect=(router.endpoint,)), token=TOKEN, timeout_s=fleet_timeout_s()
    ) as client:
        assert client.wait_for(["jr-a", "jr-b"], timeout_s=30) == ["jr-a", "jr-b"]
        yield client


def _through(router: Router) -> list[str]:
    return ["--connect", router.endpoint, "--token", TOKEN]


def test_sessions_that_only_connect_to_one_endpoint_are_its_clients() -> None:
    assert mode_of(ZenohSettings(connect=("tcp/127.0.0.1:7447",))) == "client"
    assert mode_of(ZenohSettings(listen=("tcp/127.0.0.1:1",), connect=("tcp/127.0.0.1:2",))) == (
        "peer"
    )
    assert mode_of(ZenohSettings(connect=("tcp/127.0.0.1:1", "tcp/127.0.0.1:2"))) == "peer"
    assert mode_of(ZenohSettings(connect=("tcp/127.0.0.1:1",), mode="peer")) == "peer"


def test_fleet_list_and_status_see_the_robots_through_the_router(
    router: Router, pair: tuple[Served, Served], teacher: Fleet
) -> None:
    result = run_poppy("fleet", "list", "--json", "--connect", router.endpoint)
    assert result.code == 0, result.stderr
    assert sorted(r["name"] for r in result.json()) == ["jr-a", "jr-b"]
    result = run_poppy("fleet", "status", "--connect", router.endpoint)
    assert result.code == 0, result.stderr
    lines = {line.split()[1]: line for line in result.stdout.splitlines() if "jr-" in line}
    assert set(lines) == {"jr-a", "jr-b"}
    assert all("ok" in line and "m6:" in line for line in lines.values())


def test_the_state_streams_reach_the_teacher_through_the_router(teacher: Fleet) -> None:
    seen: dict[str, int] = {}

    def count(name: str, state: Any) -> None:
        seen[name] = seen.get(name, 0) + 1

    teacher.on_state(count)
    assert eventually(lambda: min(seen.get("jr-a", 0), seen.get("jr-b", 0)) >= 20, timeout_s=20)


def test_fleet_run_play_and_stop_through_the_router(
    router: Router, pair: tuple[Served, Served], teacher: Fleet
) -> None:
    for served in pair:
        robot = from_remote(
            "zenoh:" + served.name, token=TOKEN, zenoh=ZenohSettings(connect=(router.endpoint,))
        )
        try:
            robot.moves.record("wave")
            time.sleep(0.3)
            robot.moves.save("wave")
        finally:
            robot.close()
    result = run_poppy("fleet", "run", "dance", "--robots", "jr-a,jr-b", *_through(router))
    assert result.code == 0, result.stderr
    assert all("dance" in s.servers.service.running_primitives() for s in pair)
    result = run_poppy("fleet", "stop", "--all", *_through(router))
    assert result.code == 0, result.stderr
    assert not any(s.servers.service.running_primitives() for s in pair)
    result = run_poppy("fleet", "play", "wave", "--all", *_through(router))
    assert result.code == 0, result.stderr
    assert "jr-a: playing wave" in result.stdout and "jr-b: playing wave" in result.stdout
    result = run_poppy("fleet", "play", "nothing-here", "--robots", "jr-b", *_through(router))
    assert result.code == 1
    assert "jr-b:" in result.stdout + result.stderr


def test_from_remote_drives_a_robot_through_the_router(
    router: Router, pair: tuple[Served, Served]
) -> None:
    a, _ = pair
    robot = from_remote("zenoh:jr-a", token=TOKEN, zenoh=ZenohSettings(connect=(router.endpoint,)))
    try:
        assert [m.name for m in robot.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]
        robot.compliant = False
        robot.goto_position({"m1": 25.0}, 0.2, wait=True)
        assert eventually(lambda: abs(a.robot.m1.present_position - 25.0) < 1.0)
    finally:
        robot.close()


def test_teleop_across_robots_through_the_router(
    router: Router, pair: tuple[Served, Served]
) -> None:
    from tests.teleop.hands import Hand

    a, b = pair
    Hand(a.robot).put({"m1": 30.0})
    result = run_poppy(
        "teleop",
        "--leader",
        "zenoh:jr-a",
        "--follower",
        "zenoh:jr-b",
        "--duration",
        "3",
        "--connect",
        router.endpoint,
        "--json",
        env={"POPPY_TOKEN": TOKEN},
    )
    assert result.code == 0, result.stderr
    assert result.json()["follower"] == "zenoh:jr-b"
    assert not b.robot.m1.compliant
    assert abs(b.robot.m1.goal_position - 30.0) < 1.0


def test_the_page_lists_the_fleet_it_sees_through_the_router(
    router: Router, pair: tuple[Served, Served]
) -> None:
    import httpx

    with from_profile("ergo-jr", sim=True) as robot:
        spec = ServeSpec(
            http=Listen(port=0), zenoh=ZenohSettings(connect=(router.endpoint,)), name="jr-page"
        )
        servers = serve(robot, spec)
        try:
            assert servers.http is not None
            url = f"{servers.http.url}/api/v1/web/fleet"

            def listed() -> list[str]:
                return sorted(r["name"] for r in httpx.get(url, timeout=http_timeout(5)).json())

            assert eventually(lambda: listed() == ["jr-a", "jr-b", "jr-page"], timeout_s=20)
        finally:
            servers.stop()


def test_a_router_and_a_robot_linked_directly_make_one_fleet(
    router: Router, pair: tuple[Served, Served]
) -> None:
    direct = Served("jr-c")  # listens; not on the router
    try:
        settings = ZenohSettings(connect=(router.endpoint, direct.endpoint))
        with Fleet(settings, token=TOKEN, timeout_s=fleet_timeout_s()) as client:
            names = ["jr-a", "jr-b", "jr-c"]
            assert client.wait_for(names, timeout_s=30) == names
            outcomes = client.command(
                names, "PUT", "/api/v1/robot/compliant", {"compliant": False}, together=False
            )
            assert [(o.name, o.ok) for o in outcomes] == [(n, True) for n in names], outcomes
            assert not direct.robot.compliant and not pair[0].robot.compliant
    finally:
        direct.close()


def _serve_process(name: str, router: Router) -> subprocess.Popen[Any]:
    return subprocess.Popen(
        [
            *POPPY,
            *("serve", "--zenoh", "--name", name, "--zenoh-connect", router.endpoint),
            *("--profile", "ergo-jr", "--sim"),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=dict(os.environ, **command_env()),
    )


def test_a_robot_started_before_its_router_joins_when_the_router_comes(moves: Path) -> None:
    router = Router(start=False)
    proc = _serve_process("early", router)
    try:
        assert proc.stderr is not None
        waited = read_until(proc.stderr.fileno(), "waiting for it", 60, proc)
        assert "no Zenoh router answers at" in waited, waited
        router.start()
        with Fleet(
            ZenohSettings(connect=(router.endpoint,)), timeout_s=fleet_timeout_s()
        ) as client:
            assert client.wait_for(["early"], timeout_s=30) == ["early"]
    finally:
        reap(proc)
        router.kill()


def test_robots_and_the_router_restarting_rejoin(moves: Path) -> None:
    router = Router()  # its own: restarted here
    proc = _serve_process("phoenix", router)
    steady = Served("steady", router=router.endpoint)
    try:
        with Fleet(
            ZenohSettings(connect=(router.endpoint,)), token=TOKEN, timeout_s=fleet_timeout_s()
        ) as client:
            assert client.wait_for(["phoenix", "steady"], timeout_s=60) == ["phoenix", "steady"]
            reap(proc)  # the robot restarts
            assert eventually(lambda: "phoenix" not in client.names(), timeout_s=15)
            proc = _serve_process("phoenix", router)
            assert client.wait_for(["phoenix"], timeout_s=60) == ["phoenix"]
            router.restart()  # the router restarts: the robots and the teacher rejoin it
            began = time.monotonic()
            assert client.wait_for(["phoenix", "steady"], timeout_s=30) == ["phoenix", "steady"]
            print(f"rejoined {time.monotonic() - began:.2f} s after the router came back")
            outcomes = client.command(["steady"], "GET", "/api/v1/robot", together=False)
            assert outcomes[0].ok, outcomes
    finally:
        reap(proc)
        steady.close()
        router.kill()


def test_the_router_refuses_a_busy_port_in_one_line(router: Router) -> None:
    result = run_poppy("fleet", "router", "--listen", router.endpoint)
    assert result.code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "cannot start the Zenoh router" in lines[0], lines


def test_a_fleet_command_without_its_router_is_one_line() -> None:
    from tests.helpers.zenoh_served import free_endpoint

    endpoint = free_endpoint()
    result = run_poppy("fleet", "list", "--connect", endpoint)
    assert result.code == 2
    lines = result.stderr.strip().splitlines()
    assert lines == [
        f"error: no Zenoh router or robot answers at {endpoint}: start the router (zenohd, or "
        "poppy fleet router) or the robot there, or check the endpoint"
    ], lines
