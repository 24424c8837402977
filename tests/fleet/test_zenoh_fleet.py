"""Robots on Zenoh (`poppy serve --zenoh`): found, described, driven and watched together.

Loopback only, explicit endpoints, scouting off: each robot listens on its own free port and
the fleet's client connects to them.
"""

from __future__ import annotations

import asyncio
import json
import os
import socket
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

from poppy_core import from_profile
from poppy_core.assembly import ServeSpec, ZenohSettings, serve
from poppy_core.errors import BusTimeout, CommunicationError, UnknownMotorError
from poppy_core.remote import RemoteRobot
from poppy_core.remote.zenoh_fleet import Fleet
from poppy_core.robot import from_remote
from poppy_core.zenoh_wire import ZenohSettings as Settings
from poppy_core.zenoh_wire import check_name, pack_state, session_config, unpack_state
from tests.helpers.cli import POPPY, Result, command_env, run_poppy
from tests.helpers.processes import reap
from tests.helpers.waiting import eventually, http_timeout, scaled
from tests.helpers.zenoh_served import TOKEN, Served, connect_to, fleet_timeout_s, free_endpoint

pytest.importorskip("zenoh")


def _fleet_args(*served: Served) -> list[str]:
    return [arg for s in served for arg in ("--connect", s.endpoint)]


def test_two_served_robots_are_in_fleet_list_json(two: tuple[Served, Served], fleet: Fleet) -> None:
    result = run_poppy("fleet", "list", "--json", *_fleet_args(*two))
    assert result.code == 0, result.stderr
    rows = {row["name"]: row for row in result.json()}
    assert set(rows) == {"jr-a", "jr-b"}
    assert rows["jr-a"]["creature"] == "ergo-jr"
    assert rows["jr-a"]["motors"] == 6
    assert rows["jr-b"]["health"] == "ok"
    assert rows["jr-a"]["endpoints"] == [two[0].endpoint]


def test_the_description_names_motors_limits_groups_primitives_and_chains(fleet: Fleet) -> None:
    described = fleet.describe(["jr-a"])["jr-a"]
    assert [m["name"] for m in described["motors"]] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    assert len(described["motors"][0]["angle_limit"]) == 2
    assert "base" in described["groups"]
    assert "dance" in described["primitives"]
    assert described["chains"] == ["chain"]
    assert described["token"] is True


def test_the_state_comes_every_cycle_in_the_packed_message(fleet: Fleet) -> None:
    seen: list[int] = []
    fleet.on_state(lambda name, state: seen.append(state.seq), name="jr-a")
    assert eventually(lambda: len(seen) >= 10, timeout_s=10)
    assert seen == sorted(seen)  # in order, from one publisher


def test_the_state_message_round_trips_and_its_version_is_checked() -> None:
    motors = {
        "m1": {
            "present_position": 1.5,
            "present_speed": 0.0,
            "present_load": -2.0,
            "present_temperature": 35.0,
            "compliant": True,
            "online": True,
        },
        "m2": {"present_position": None, "compliant": False, "online": False},
    }
    state = unpack_state(pack_state(7, 12.5, motors))
    assert state.seq == 7 and state.stamp == 12.5
    assert state.motors["m1"]["present_position"] == 1.5
    assert state.motors["m1"]["compliant"] is True
    assert state.motors["m2"] == {
        "present_position": None,
        "present_speed": None,
        "present_load": None,
        "present_temperature": None,
        "compliant": False,
        "online": False,
    }
    with pytest.raises(Exception, match="version 9"):
        unpack_state(b"\x09" + pack_state(7, 12.5, motors)[1:])
    with pytest.raises(Exception, match="not a poppy state message"):
        unpack_state(b"\x01\x02")


def test_fleet_play_starts_both_robots(two: tuple[Served, Served], fleet: Fleet) -> None:
    a, b = two
    remote = RemoteRobot("zenoh:jr-a", token=TOKEN, zenoh=Settings(connect=connect_to(a)))
    try:
        remote.moves.record("wave")
        time.sleep(0.3)
        remote.moves.save("wave")
    finally:
        remote.close()
    played: list[str] = []
    for served in (a, b):
        real = served.servers.service.moves.play

        def spy(*args: Any, real: Any = real, name: str = served.name, **kwargs: Any) -> Any:
            played.append(name)
            return real(*args, **kwargs)

        served.servers.service.moves.play = spy  # type: ignore[method-assign]
    result = run_poppy("fleet", "play", "wave", "--all", "--token", TOKEN, *_fleet_args(a, b))
    assert result.code == 0, result.stderr
    assert "jr-a: playing wave" in result.stdout and "jr-b: playing wave" in result.stdout
    assert sorted(played) == ["jr-a", "jr-b"]
    result = run_poppy(
        "fleet", "run", "dance", "--robots", "jr-a,jr-b", "--token", TOKEN, *_fleet_args(a, b)
    )
    assert result.code == 0, result.stderr
    assert all("dance" in s.servers.service.running_primitives() for s in (a, b))
    result = run_poppy("fleet", "stop", "--all", "--token", TOKEN, *_fleet_args(a, b))
    assert result.code == 0, result.stderr
    assert not any(s.servers.service.running_primitives() for s in (a, b))


def test_the_robots_of_one_command_start_at_the_shared_time(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    started: dict[str, float] = {}
    for served in two:
        dance = served.servers.service.primitive("dance")
        real = dance.setup

        def spy(real: Any = real, name: str = served.name) -> None:
            started[name] = time.time()
            real()

        dance.setup = spy  # type: ignore[method-assign]
    outcomes = fleet.command(["jr-a", "jr-b"], "POST", "/api/v1/primitives/dance/start")
    assert [o.ok for o in outcomes] == [True, True]
    assert eventually(lambda: set(started) == {"jr-a", "jr-b"})
    start_at = fleet.last_start_at
    assert start_at is not None
    # armed on arrival, fired at start_at (less a float rounding of the robot's check)
    assert all(t >= start_at - 1e-6 for t in started.values())


def test_bad_commands_are_refused_with_the_rest_wording_and_move_nothing(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    a, _ = two
    a.robot.compliant = False
    before = {m.name: m.goal_position for m in a.robot.motors}
    unknown = fleet.command(
        ["jr-a"],
        "POST",
        "/api/v1/gotos",
        {"positions": {"m9": 10}, "duration_s": 1},
        together=False,
    )[0]
    assert (unknown.ok, unknown.status) == (False, 404)
    assert unknown.message == "no motor 'm9' (motors: m1, m2, m3, m4, m5, m6)"
    nan = fleet.command(
        ["jr-a"],
        "POST",
        "/api/v1/gotos",
        {"positions": {"m1": 10}, "duration_s": -1},
        together=False,
    )[0]
    assert nan.status == 422
    with Fleet(Settings(connect=connect_to(a)), timeout_s=fleet_timeout_s()) as no_token:
        refused = no_token.command(
            ["jr-a"], "POST", "/api/v1/robot/compliant", {"compliant": True}, together=False
        )[0]
    assert refused.status == 401 and "token" in refused.message
    assert not a.robot.compliant
    # a bad message on the goal stream: refused, counted, nothing moved
    send = fleet.goals("jr-a")
    send({"m1": float("nan")})
    send({"m1": 20.0, "m9": 3.0})
    node = a.servers.zenoh
    assert node is not None
    assert eventually(lambda: node.refused_goals == 2)
    assert {m.name: m.goal_position for m in a.robot.motors} == before
    # the robot's raw queryable: a reply saying why, for what is not a request
    replies = list(fleet.session.get("poppy/jr-a/api", payload=b"{nope", timeout=3))
    answer = json.loads(replies[0].ok.payload.to_bytes())
    assert answer["status"] == 400 and "not JSON" in answer["body"]["detail"]


def test_a_zenoh_remote_robot_reads_and_moves_a_served_one(two: tuple[Served, Served]) -> None:
    a, _ = two
    remote = from_remote("zenoh:jr-a", token=TOKEN, zenoh=Settings(connect=(a.endpoint,)))
    try:
        assert [m.name for m in remote.motors] == ["m1", "m2", "m3", "m4", "m5", "m6"]
        remote.compliant = False
        assert not a.robot.compliant
        remote.goto_position({"m1": 25.0}, 0.2, wait=True)
        assert eventually(lambda: abs(a.robot.m1.present_position - 25.0) < 1.0)
        assert abs(remote.m1.present_position - 25.0) < 1.0
        with pytest.raises(UnknownMotorError):
            remote.motor("m9").goal_position = 3
    finally:
        remote.close()


def test_a_command_to_a_silent_robot_reports_within_its_timeout(two: tuple[Served, Served]) -> None:
    a, _ = two
    with pytest.raises(CommunicationError, match="no robot of that name"):
        RemoteRobot("zenoh:nobody", zenoh=Settings(connect=(a.endpoint,)), timeout_s=1)
    node = a.servers.zenoh
    assert node is not None
    held: list[Any] = []

    class Stalled:  # the robot takes the query (holding it) and never answers
        def submit(self, coroutine: Any) -> None:
            held.append(coroutine)

        def close(self) -> None:
            for coroutine in held:
                coroutine.close()

    node._caller = Stalled()  # type: ignore[assignment]
    began = time.monotonic()
    with pytest.raises(BusTimeout, match="no answer within 1 s"):
        RemoteRobot("zenoh:jr-a", token=TOKEN, zenoh=Settings(connect=(a.endpoint,)), timeout_s=1)
    assert held  # the query reached the robot
    assert time.monotonic() - began < 30  # it reports; it never hangs


def _listening(host: str, port: int) -> bool:
    try:
        with socket.create_connection((host, port), timeout=1.0):
            return True
    except OSError:
        return False


def test_a_killed_robot_leaves_the_fleet(moves: Path) -> None:
    endpoint = free_endpoint()
    proc = subprocess.Popen(
        [
            *POPPY,
            "serve",
            "--zenoh",
            "--name",
            "doomed",
            "--zenoh-listen",
            endpoint,
            "--profile",
            "ergo-jr",
            "--sim",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=dict(os.environ, **command_env()),
    )
    try:
        # one endpoint: the teacher is the robot's Zenoh client, which opens only once the robot
        # listens (3 s at most): wait for the robot's process to come up first, however loaded
        host, port = endpoint.removeprefix("tcp/").rsplit(":", 1)
        assert eventually(lambda: _listening(host, int(port)), timeout_s=60)
        with Fleet(Settings(connect=(endpoint,)), timeout_s=fleet_timeout_s()) as client:
            assert client.wait_for(["doomed"], timeout_s=60) == ["doomed"]
            proc.kill()
            assert eventually(lambda: "doomed" not in client.names(), timeout_s=15)
    finally:
        reap(proc)


def test_settings_keep_scouting_off_and_listen_only_where_told() -> None:
    config = session_config(Settings(connect=("tcp/127.0.0.1:7447",)))
    assert json.loads(config.get_json("scouting/multicast/enabled")) is False
    assert json.loads(config.get_json("scouting/gossip/enabled")) is False
    assert json.loads(config.get_json("listen/endpoints")) == []
    with pytest.raises(Exception, match="not a Zenoh endpoint"):
        Settings(listen=("127.0.0.1:7447",))
    with pytest.raises(Exception, match="not a robot name"):
        check_name("a/b")


def test_serve_refuses_zenoh_options_without_zenoh() -> None:
    result = run_poppy("serve", "--http", "--zenoh-listen", "tcp/127.0.0.1:1", "--sim")
    assert result.code == 2
    assert "need --zenoh" in result.stderr


def test_teleop_across_two_served_robots(two: tuple[Served, Served]) -> None:
    """`poppy teleop --leader zenoh:A --follower zenoh:B`: B copies A moved by hand; when A's
    state stops (the link stalls), B holds where it is and says so."""
    from poppy_core.motion.teleop.session import Teleoperation
    from poppy_core.remote.zenoh_teleop import ZenohFollower, ZenohLeader
    from tests.teleop.hands import Hand

    a, b = two
    settings = Settings(connect=connect_to(a, b))
    # the first state within 3 s times the load (a loaded run waited longer)
    leader = ZenohLeader("jr-a", TOKEN, settings=settings, timeout_s=scaled(3.0))
    follower = ZenohFollower("jr-b", TOKEN, settings=settings, ramp_s=0.2, timeout_s=scaled(3.0))
    changes: list[str] = []
    run = Teleoperation(leader, follower, rate_hz=100, on_change=lambda s, r: changes.append(s))
    try:
        run.start()
        assert eventually(lambda: a.robot.m1.compliant and not b.robot.m1.compliant, timeout_s=10)
        Hand(a.robot).put({"m1": 30.0, "m2": -20.0})
        assert eventually(lambda: abs(b.robot.m1.goal_position - 30.0) < 1.0, timeout_s=10)
        assert eventually(lambda: abs(b.robot.m2.goal_position + 20.0) < 1.0, timeout_s=10)
        node = a.servers.zenoh
        assert node is not None
        node._worker.close()  # the leader's state stops: the watchdog holds the follower
        assert eventually(lambda: "leader lost" in changes, timeout_s=10)
        held = b.robot.m1.goal_position
        Hand(a.robot).put({"m1": -40.0})
        time.sleep(0.3)
        assert b.robot.m1.goal_position == held
    finally:
        run.stop()
        leader.close()
        follower.close()


def test_a_leader_whose_state_never_comes_is_refused_in_one_line(
    two: tuple[Served, Served],
) -> None:
    from poppy_core.remote.zenoh_teleop import ZenohLeader

    a, _ = two
    node = a.servers.zenoh
    assert node is not None
    node._worker.close()  # it answers its api, but publishes no state
    with pytest.raises(CommunicationError, match=r"^zenoh:jr-a: no state message within 1 s$"):
        ZenohLeader("jr-a", TOKEN, settings=Settings(connect=(a.endpoint,)), timeout_s=1.0)


def teleop_a_to_b(a: Served, b: Served) -> Result:
    """`poppy teleop` of half a second, A leading and B following, both on Zenoh."""
    args = ["--leader", "zenoh:jr-a", "--follower", "zenoh:jr-b", "--duration", "0.5"]
    connect = ["--connect", a.endpoint, "--connect", b.endpoint]
    return run_poppy("teleop", *args, *connect, "--json", env={"POPPY_TOKEN": TOKEN})


def test_poppy_teleop_takes_zenoh_robots(two: tuple[Served, Served]) -> None:
    a, b = two
    result = teleop_a_to_b(a, b)
    assert result.code == 0, result.stderr
    summary = result.json()
    assert summary["follower"] == "zenoh:jr-b"
    assert not b.robot.m1.compliant


def test_poppy_teleop_waits_for_a_robot_slow_to_answer_as_long_as_remote_clients_do(
    two: tuple[Served, Served], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A follower that answers its first request after 4 s (a robot busy starting, a loaded
    machine) is taken: teleop waits as long as every other remote client (10 s), not 3 s."""
    a, b = two
    node = b.servers.zenoh
    assert node is not None
    answer = node._call
    delayed: list[str] = []

    async def slow_first_answer(caller: Any, request: Any) -> dict[str, Any]:
        if not delayed:
            delayed.append(request.path)
            await asyncio.sleep(4.0)
        return await answer(caller, request)

    monkeypatch.setattr(node, "_call", slow_first_answer)
    result = teleop_a_to_b(a, b)
    assert delayed == ["/api/v1/motors"]
    assert result.code == 0, result.stderr
    assert result.json()["follower"] == "zenoh:jr-b"


def test_remote_zenoh_works_where_remote_url_does(two: tuple[Served, Served]) -> None:
    a, _ = two
    env = {"POPPY_ZENOH_CONNECT": a.endpoint, "POPPY_TOKEN": TOKEN}
    result = run_poppy("robot", "status", "--remote", "zenoh:jr-a", "--json", env=env)
    assert result.code == 0, result.stderr
    assert [m["name"] for m in result.json()["motors"]] == ["m1", "m2", "m3", "m4", "m5", "m6"]
    result = run_poppy("primitive", "list", "--remote", "zenoh:jr-a", "--json", env=env)
    assert result.code == 0, result.stderr
    assert "dance" in {p["name"] for p in result.json()}


def test_a_served_camera_is_read_over_zenoh_as_over_http(two: tuple[Served, Served]) -> None:
    """``RemoteRobot.camera_image`` over Zenoh: the ``frame.png`` route's bytes, the served
    camera's frame pixel for pixel (what the LeRobot plugin's ``robot_cameras`` read)."""
    import cv2
    import numpy as np

    from poppy_core.remote import RemoteRobot

    a, _ = two
    expected = next(s for s in a.robot.sensors if s.name == "camera").latest(10.0).image
    with RemoteRobot("zenoh:jr-a", token=TOKEN, zenoh=ZenohSettings(connect=(a.endpoint,))) as rr:
        assert rr.camera_names() == ["camera"]
        png = rr.camera_image("camera")
    decoded = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    assert decoded.shape == expected.shape and (decoded == expected).all()


def test_the_page_lists_the_robots_its_fleet_sees(moves: Path) -> None:
    """`/api/v1/web/fleet`: every robot on the network, with a link to the pages served."""
    import httpx

    from poppy_core.assembly import Listen

    b = Served("jr-b", token=None)
    endpoint = free_endpoint()
    with from_profile("ergo-jr", sim=True) as robot:
        spec = ServeSpec(
            http=Listen(port=0),
            zenoh=ZenohSettings(listen=(endpoint,), connect=(b.endpoint,)),
            name="jr-a",
        )
        servers = serve(robot, spec)
        try:
            assert servers.http is not None
            url = f"{servers.http.url}/api/v1/web/fleet"

            def listed() -> list[dict[str, Any]]:
                return list(httpx.get(url, timeout=http_timeout(5)).json())

            assert eventually(lambda: [r["name"] for r in listed()] == ["jr-a", "jr-b"], 10)
            rows = {r["name"]: r for r in listed()}
            assert rows["jr-a"]["self"] and rows["jr-a"]["page"] == servers.http.url
            assert rows["jr-b"]["creature"] == "ergo-jr" and rows["jr-b"]["page"] is None
            b.close()
            assert eventually(lambda: [r["name"] for r in listed()] == ["jr-a"], 10)
        finally:
            servers.stop()


def test_fleet_status_shows_every_robot_and_its_motors(
    two: tuple[Served, Served], fleet: Fleet
) -> None:
    result = run_poppy("fleet", "status", *_fleet_args(*two))
    assert result.code == 0, result.stderr
    lines = {line.split()[1]: line for line in result.stdout.splitlines() if "jr-" in line}
    assert set(lines) == {"jr-a", "jr-b"}
    assert all("ok" in line and "m6:" in line for line in lines.values())


def test_fleet_commands_name_their_robots() -> None:
    result = run_poppy("fleet", "stop", "--connect", free_endpoint())
    assert result.code == 2
    assert "--all, or --robots a,b" in result.stderr


def test_a_busy_zenoh_endpoint_is_one_clear_line(moves: Path) -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        endpoint = f"tcp/127.0.0.1:{busy.getsockname()[1]}"
        result = run_poppy(
            "serve",
            "--zenoh",
            "--name",
            "x",
            "--zenoh-listen",
            endpoint,
            "--sim",
            "--profile",
            "ergo-jr",
        )
    assert result.code == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Address already in use" in lines[0], lines
    assert " at /" not in lines[0]


def test_a_robot_listening_on_every_interface_announces_its_addresses(
    two: tuple[Served, Served], fleet: Fleet, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`poppy serve --host 0.0.0.0 --zenoh-listen tcp/0.0.0.0:7447`: its description names the
    addresses a peer dials (this machine's), never the wildcard, and its page is a link."""
    from poppy_core import checks
    from poppy_core.server import reachable
    from poppy_core.server.zenoh.web_fleet import announced_hosts

    monkeypatch.setattr(reachable, "machine_addresses", lambda: ["192.0.2.7", "198.51.100.3"])
    node = two[0].servers.zenoh
    assert node is not None
    node.endpoints = ("tcp/0.0.0.0:7447", "tcp/[::]:7448#iface=wlan0", "tcp/127.0.0.1:7449")
    node.page = "http://0.0.0.0:8080"  # what the builder takes from an HTTP server on 0.0.0.0
    described = fleet.describe(["jr-a"])["jr-a"]
    assert described["endpoints"] == [
        "tcp/192.0.2.7:7447",
        "tcp/198.51.100.3:7447",
        "tcp/192.0.2.7:7448#iface=wlan0",
        "tcp/198.51.100.3:7448#iface=wlan0",
        "tcp/127.0.0.1:7449",
    ]
    assert described["page"] == "http://192.0.2.7:8080"
    assert checks.peer_page(described["page"], announced_hosts("jr-a", described))
    result = run_poppy("fleet", "list", "--json", *_fleet_args(*two))
    assert result.code == 0, result.stderr
    rows = {row["name"]: row for row in result.json()}
    assert "0.0.0.0" not in json.dumps(rows["jr-a"])
