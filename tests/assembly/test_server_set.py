"""One server set: the creature classes and `poppy serve` build it with the same ``serve()``,
one service (so one teleoperation registry) behind every protocol."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from websockets.sync.client import ClientConnection, connect

from poppy_core import assembly, from_profile
from poppy_core.assembly import Listen, ServerSet, ServeSpec, pypot_creatures
from poppy_core.pypot import PoppyErgoJr
from tests.helpers.cli import run_poppy

EVERY = ("http", "ws", "zmq", "snap")


@pytest.fixture
def built(monkeypatch: pytest.MonkeyPatch) -> list[tuple[ServeSpec, ServerSet]]:
    """Every (spec, server set) ``serve`` built, whichever path called it."""
    seen: list[tuple[ServeSpec, ServerSet]] = []
    real = assembly.serve

    def spy(robot: Any, spec: ServeSpec, **options: Any) -> ServerSet:
        servers = real(robot, spec, **options)
        seen.append((spec, servers))
        return servers

    monkeypatch.setattr(assembly, "serve", spy)
    monkeypatch.setattr(pypot_creatures, "serve", spy)
    return seen


def _shape(servers: ServerSet) -> dict[str, str]:
    """Protocol -> the type of its server, each checked to use the set's one service."""
    for name, server in servers.servers.items():
        assert server.service is servers.service, name
    return {name: type(server).__name__ for name, server in servers.servers.items()}


def test_the_creature_path_and_the_cli_path_give_the_same_server_set(
    built: list[tuple[ServeSpec, ServerSet]], monkeypatch: pytest.MonkeyPatch
) -> None:
    ports = {f"{name}_port": 0 for name in EVERY}
    with PoppyErgoJr(
        simulator="dummy", use_http=True, use_ws=True, use_zmq=True, use_snap=True, **ports
    ) as robot:
        ((creature_spec, creature_set),) = built
        assert {name: getattr(robot, name) for name in EVERY} == creature_set.servers
        creature_shape = _shape(creature_set)
        assert creature_set.running
    assert not any(server_running for server_running in _states(creature_set))

    def stop_at_once(servers: list[Any], stop: Any) -> None:  # `poppy serve` waits here
        assert all(s.running for s in servers)

    monkeypatch.setattr("poppy_cli.commands.serve._wait_for_signal", stop_at_once)
    args = ["serve", "--sim", "--profile", "ergo-jr", "--http", "--ws", "--zmq", "--snap"]
    args += [f"--{name}-port=0" for name in EVERY]
    result = run_poppy(*args)
    assert result.code == 0, result.stderr
    ((cli_spec, cli_set),) = built[1:]
    assert cli_spec == creature_spec
    assert (
        _shape(cli_set)
        == creature_shape
        == {
            "http": "BackgroundServer",
            "ws": "BackgroundServer",
            "zmq": "ZmqRobotServer",
            "snap": "SnapServer",
        }
    )
    assert cli_set.app.state.service is cli_set.service
    assert not any(_states(cli_set))


def _states(servers: ServerSet) -> list[bool]:
    return [s.running for s in servers.servers.values()]


def _teleop(ws: ClientConnection, motor: str) -> dict[str, Any]:
    """Ask for ``motor`` and give the server's answer (started, or the refusal)."""
    ws.send(json.dumps({"type": "teleop.start", "motors": [motor], "client": str(id(ws))}))
    while True:
        message = json.loads(ws.recv(timeout=10))
        if message.get("type") == "teleop.started" or "error" in message:
            return dict(message)


@pytest.fixture
def ergo_served_twice() -> Iterator[tuple[str, str]]:
    """A virtual Ergo Jr built with use_http and use_ws: its two WebSocket URLs."""
    with PoppyErgoJr(
        simulator="dummy", use_http=True, http_port=0, use_ws=True, ws_port=0
    ) as robot:
        http_port, ws_port = robot.http.port, robot.ws.port
        yield f"ws://127.0.0.1:{http_port}/api/v1/ws", f"ws://127.0.0.1:{ws_port}/"


@pytest.mark.parametrize("second", [0, 1], ids=["same port", "other port"])
def test_two_websocket_clients_cannot_teleoperate_one_motor(
    ergo_served_twice: tuple[str, str], second: int
) -> None:
    """Whether the second client comes through the HTTP port's stream or pypot's WebSocket
    port, the motor is already taken."""
    first_url = ergo_served_twice[1]
    with connect(first_url) as first, connect(ergo_served_twice[second]) as other:
        assert _teleop(first, "m1").get("type") == "teleop.started"
        refused = _teleop(other, "m1")
        assert "m1 is driven by teleop from 127.0.0.1" in str(refused.get("error")), refused


def test_a_busy_port_stops_the_servers_already_bound() -> None:
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        busy = taken.getsockname()[1]
        with from_profile("ergo-jr", sim=True, sensors=False) as robot:
            from poppy_core.server import ListenError

            spec = ServeSpec(http=Listen(port=0), ws=Listen(port=busy))
            with pytest.raises(ListenError, match="already in use"):
                assembly.serve(robot, spec)
            # the HTTP port bound first was released: a second set can be served
            with assembly.serve(robot, ServeSpec(http=Listen(port=0))) as servers:
                assert servers.running


def test_stopping_the_set_stops_the_service_after_every_server(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    order: list[str] = []
    with from_profile("ergo-jr", sim=True, sensors=False) as robot:
        servers = assembly.serve(robot, ServeSpec(http=Listen(port=0), ws=Listen(port=0)))
        for name, server in servers.servers.items():
            _record(monkeypatch, server, "stop", order, name)
        _record(monkeypatch, servers.service, "close", order, "service")
        servers.stop()
        servers.stop()
    assert order == ["ws", "http", "service"]


def _record(
    monkeypatch: pytest.MonkeyPatch, target: Any, method: str, order: list[str], name: str
) -> None:
    real: Callable[[], None] = getattr(target, method)

    def recorded() -> None:
        order.append(name)
        real()

    monkeypatch.setattr(target, method, recorded)


def test_mdns_announces_the_tcp_ports_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """A set's servers are ``Server``s: Zenoh's (and ROS 2's) port is None, and no ``zenoh=None``
    goes into the announcement's TXT record."""
    from poppy_core.assembly.server_builders import name_and_announce
    from poppy_core.server import RobotService, announce

    announced: dict[str, int] = {}

    class Announcer:
        def __init__(self, name: str, ports: dict[str, int], **options: Any) -> None:
            announced.update(ports)

        def start(self) -> None:
            pass

    class Served:
        def __init__(self, port: int | None) -> None:
            self.port, self.url, self.running = port, "x", True

        def start(self) -> None:
            pass

        def stop(self) -> None:
            pass

        def rename(self, name: str) -> None:
            pass

    monkeypatch.setattr(announce, "Announcer", Announcer)
    spec = ServeSpec(name="jr", announce=True)
    with from_profile("ergo-jr", sim=True, sensors=False) as robot:
        servers = ServerSet(RobotService(robot), spec.policy(), None)
        servers.servers.update({"http": Served(8080), "zenoh": Served(None)})
        name_and_announce(servers, robot, spec)
        servers.service.close()
    assert announced == {"http": 8080}
