"""``poppy serve --announce`` over mDNS on loopback only (zeroconf bound to 127.0.0.1):
the robot's ``NAME.local`` resolves, its ``_poppy._tcp`` service carries what it is, a second
robot of the same name gets ``NAME-2`` and answers to it, and stopping withdraws the records."""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterator

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, serve
from poppy_core.remote.discovery import AnnouncedRobot, discover, resolve
from poppy_core.robot import Robot
from tests.helpers.waiting import eventually, http_timeout

pytest.importorskip("zeroconf")

LOOPBACK = ["127.0.0.1"]


def unique_name() -> str:
    """A name no other test run on this machine announces at the same time."""
    return f"t{os.getpid()}-{uuid.uuid4().hex[:6]}"


@pytest.fixture
def robots() -> Iterator[list[Robot]]:
    made: list[Robot] = []
    yield made
    for robot in made:
        robot.close()


def _served(robots: list[Robot], name: str, token: str | None = None) -> ServerSet:
    robot = from_profile("ergo-jr", sim=True)
    robots.append(robot)
    spec = ServeSpec(http=Listen(), ws=Listen(), name=name, announce=True, token=token)
    return serve(robot, spec)


def _found(name: str) -> AnnouncedRobot | None:
    for robot in discover(2.5, interfaces=LOOPBACK):
        if robot.name == name:
            return robot
    return None


def test_the_robot_is_announced_with_what_it_is(robots: list[Robot]) -> None:
    name = unique_name()
    with _served(robots, name, token="s3cret") as servers:
        assert servers.announcer is not None and servers.announcer.name == name
        found: list[AnnouncedRobot] = []
        assert eventually(lambda: bool(found.append(_found(name)) or found[-1]), 20.0)
        robot = found[-1]
        assert robot is not None
        assert robot.host == f"{name}.local"
        assert robot.creature == "ergo-jr"
        assert robot.version
        assert robot.token is True  # that one is asked for, never what it is
        assert robot.addresses == ("127.0.0.1",)
        assert servers.http is not None and servers.ws is not None
        assert robot.ports == {"http": servers.http.port, "ws": servers.ws.port}
        assert robot.urls["http"] == f"http://{name}.local:{servers.http.port}/"
        assert resolve(f"{name}.local", 3.0, interfaces=LOOPBACK) == ["127.0.0.1"]
    assert eventually(lambda: resolve(f"{name}.local", 1.0, interfaces=LOOPBACK) == [], 20.0)


def test_a_taken_name_gets_a_suffix_and_the_server_answers_to_it(robots: list[Robot]) -> None:
    name = unique_name()
    with _served(robots, name) as first, _served(robots, name) as second:
        assert first.announcer is not None and first.announcer.name == name
        assert second.announcer is not None and second.announcer.name == f"{name}-2"
        assert second.http is not None
        port = second.http.port
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=http_timeout()) as http:
            for host in (f"{name}-2.local:{port}", f"{name}-2"):
                assert http.get("/api/v1/robot", headers={"Host": host}).status_code == 200
            assert http.get("/api/v1/robot", headers={"Host": "other.local"}).status_code == 400
        assert resolve(f"{name}-2.local", 3.0, interfaces=LOOPBACK) == ["127.0.0.1"]


def test_nothing_is_announced_unless_asked(robots: list[Robot]) -> None:
    robot = from_profile("ergo-jr", sim=True)
    robots.append(robot)
    with serve(robot, ServeSpec(http=Listen(), snap=Listen(), name="quiet")) as servers:
        assert servers.announcer is None
        assert servers.http is not None and servers.snap is not None
        for port, path in ((servers.http.port, "/api/v1/robot"), (servers.snap.port, "/ip/")):
            with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=http_timeout()) as http:
                for host in ("quiet.local", "evil.example"):
                    answer = http.get(path, headers={"Host": f"{host}:{port}"})
                    # named, every server answers its name (Snap!'s blocks call poppy.local)
                    assert answer.status_code == (200 if host == "quiet.local" else 400), path
