"""One argument/error contract: the same bad arguments (NaN, inf, negative, zero, huge, unknown
names) through the Python API, the CLI, REST (v1 and pypot's routes), the WebSocket, Snap!,
ZMQ, Zenoh (its ``api`` queryable and its goal stream) and ROS 2 (``joint_command`` and
``joint_trajectory``) give the same KIND of refusal, or the same clamp (docs/rest.md,
"Arguments and errors"; docs/internals.md, "The limit rule").

Kinds: ``invalid`` (an ``ArgumentError``: 422 on v1, 400 on pypot's routes and Snap!),
``not_found`` (an ``UnknownNameError``: 404), ``accepted`` (the call went through). A goal
beyond the angle limits is ``accepted`` and clamped: the motor aims at the limit. The servers
and the robot are the ones of tests/server/test_hostile_numbers.py (its ``surfaces`` fixture);
the same robot is also served on Zenoh and as a ROS 2 node (``network``, loopback only).
"""

from __future__ import annotations

import json
import math
import queue
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import pytest
from websockets.sync.client import connect

from poppy_core.errors import ArgumentError, PoppyError, UnknownNameError
from poppy_core.motion import attached_primitive, load_move
from poppy_core.motion.leases import motor_leases
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import eventually
from tests.helpers.zenoh_served import free_endpoint
from tests.server.conftest import moves_folder  # noqa: F401  (the fixture `surfaces` needs)
from tests.server.test_hostile_numbers import Surfaces, surfaces  # noqa: F401

LIMIT = 150.0
"""The Ergo Jr's m1 angle limit (both ways): where a goal beyond it is clamped."""

Outcome = tuple[str, str]
"""(kind, what the surface said)."""
Send = Callable[[Surfaces], Outcome]

V1_KINDS = {422: "invalid", 400: "invalid", 404: "not_found", 409: "conflict"}
PYPOT_KINDS = {400: "invalid", 404: "not_found"}


@dataclass(frozen=True)
class V1:
    """A v1 request: sent over HTTP, and the same over Zenoh's ``api`` queryable."""

    method: str
    path: str
    body: str | None = None

    def __call__(self, s: Surfaces) -> Outcome:
        headers = {"Content-Type": "application/json"}
        answer = s.http.request(self.method, self.path, content=self.body, headers=headers)
        return _http_kind(answer.status_code, answer.text, V1_KINDS)


@dataclass(frozen=True)
class Case:
    """One bad (or clamped) argument and how each surface is asked it (None: not on it)."""

    name: str
    kind: str
    python: Send | None = None
    cli: Send | None = None
    rest_v1: V1 | None = None
    rest_pypot: Send | None = None
    ws: Send | None = None
    snap: Send | None = None
    zmq: Send | None = None
    zenoh_goals: Send | None = None
    ros2: Send | None = None

    @property
    def zenoh_api(self) -> Send | None:
        """The v1 request, through the Zenoh ``api`` queryable."""
        return None if self.rest_v1 is None else zenoh_api(self.rest_v1)


SURFACES = (
    "python",
    "cli",
    "rest_v1",
    "rest_pypot",
    "ws",
    "snap",
    "zmq",
    "zenoh_api",
    "zenoh_goals",
    "ros2",
)
NETWORK = ("zenoh_api", "zenoh_goals", "ros2")
"""The surfaces of the ``network`` fixture (Zenoh and ROS 2 on loopback)."""


@dataclass
class Network:
    """The robot of ``surfaces`` served on Zenoh as ``poppy/jr1`` and as the ROS 2 node
    ``/jr1``, and a client session on loopback."""

    servers: Any
    session: Any
    ros2: Any
    """A ROS 2 client (tests/ros2/rmw_client.Client)."""


@pytest.fixture(scope="module")
def network(surfaces: Surfaces) -> Iterator[Network]:  # noqa: F811  (the fixture imported below)
    pytest.importorskip("zenoh")
    pytest.importorskip("rosbags")
    from poppy_core.assembly import ServeSpec, serve
    from poppy_core.ros2_wire import Ros2Settings
    from poppy_core.zenoh_wire import ZenohSettings
    from tests.ros2.rmw_client import Client
    from tests.ros2.test_ros2_node import client_session

    endpoint = free_endpoint()
    spec = ServeSpec(zenoh=ZenohSettings(listen=(endpoint,)), ros2=Ros2Settings(), name="jr1")
    servers = serve(surfaces.robot, spec)
    session = client_session(endpoint)
    client = Client(session, 0)
    try:
        yield Network(servers, session, client)
    finally:
        client.close()
        session.close()
        servers.stop()


# -- how each surface is asked, and how its answer reads as a kind ----------------------------


def python(call: Callable[[Any], object]) -> Send:
    def send(s: Surfaces) -> Outcome:
        try:
            call(s.robot)
        except UnknownNameError as exc:
            return "not_found", str(exc)
        except ArgumentError as exc:
            return "invalid", str(exc)
        except PoppyError as exc:  # a refusal of another type breaks the contract
            return f"other {type(exc).__name__}", str(exc)
        return "accepted", ""

    return send


def cli(*args: str) -> Send:
    def send(s: Surfaces) -> Outcome:
        result = run_poppy(*args, "--sim", "ideal", "--profile", "ergo-jr")
        if result.code == 0:
            return "accepted", result.stdout
        lines = result.stderr.strip().splitlines()
        if len(lines) != 1 or not lines[0].startswith("error: ") or "Traceback" in result.stderr:
            return "unclear", result.stderr
        # The CLI has no status: an unknown name is the one line "no <kind> '<name>' (...)".
        unknown = any(f"no {kind} '" in lines[0] for kind in ("motor", "primitive", "move"))
        return ("not_found" if unknown else "invalid"), lines[0]

    return send


def _http_kind(status: int, text: str, kinds: dict[int, str]) -> Outcome:
    if 200 <= status < 300:
        return "accepted", text
    if "\n" in text.strip() or "internal" in text:
        return "unclear", text
    return kinds.get(status, f"status {status}"), text


def rest_v1(method: str, path: str, body: str | None = None) -> V1:
    return V1(method, path, body)


def rest_pypot(method: str, path: str, body: str | None = None) -> Send:
    def send(s: Surfaces) -> Outcome:
        answer = s.http.request(method, path, content=body)
        return _http_kind(answer.status_code, answer.text, PYPOT_KINDS)

    return send


def snap(path: str) -> Send:
    def send(s: Surfaces) -> Outcome:
        answer = s.snap.get(path)
        return _http_kind(answer.status_code, answer.text, PYPOT_KINDS)

    return send


def ws(command: str) -> Send:
    """A WebSocket write; then a probe (not JSON) whose error frame says the write was taken."""

    def send(s: Surfaces) -> Outcome:
        with connect(s.ws_url + "?rate_hz=0.2") as socket:
            socket.send(command)
            socket.send("probe")
            for _ in range(50):
                frame = json.loads(socket.recv(timeout=10))
                if "error" not in frame:
                    continue  # a state frame
                if "JSON syntax error" in frame["error"]:  # the probe's answer
                    return "accepted", ""
                return frame.get("kind", "no kind"), frame["error"]
        return "unclear", "no frame"

    return send


def zmq(method: str, **arguments: Any) -> Send:
    def send(s: Surfaces) -> Outcome:
        request = json.dumps({"robot": {method: arguments}})
        answer = json.loads(s.zmq.reply_to(request.encode()))
        if isinstance(answer, dict) and "error" in answer:
            return answer.get("kind", "no kind"), answer["error"]
        return "accepted", json.dumps(answer)

    return send


def zenoh_api(request: V1) -> Send:
    """The v1 request as a query to ``poppy/jr1/api``; its answer's status read as on v1."""

    def send(s: Surfaces, n: Network) -> Outcome:
        from poppy_core import zenoh_wire
        from poppy_core.remote.zenoh_client import answer_of

        body = None if request.body is None else json.loads(request.body)
        payload = zenoh_wire.api_request(request.method, request.path, body)
        replies = list(n.session.get("poppy/jr1/api", payload=payload, timeout=20.0))
        status, answer = answer_of("jr1", replies, 20.0, 0.0)
        return _http_kind(status, json.dumps(answer), V1_KINDS)

    return send  # type: ignore[return-value]


def _heard(owner: Any, method: str, send: Callable[[], None]) -> tuple[str, BaseException | None]:
    """Call ``send`` (a message with no answer), and hear what ``owner.method`` (the handler
    the message reaches, spied on for this one call) did with it: returned, or raised."""
    heard: queue.Queue[tuple[str, BaseException | None]] = queue.Queue()
    real = getattr(owner, method)

    def spy(*args: Any, **kwargs: Any) -> Any:
        try:
            result = real(*args, **kwargs)
        except Exception as exc:
            heard.put(("raised", exc))
            raise
        heard.put(("accepted", None))
        return result

    setattr(owner, method, spy)
    try:
        for _ in range(3):  # a first message of a new publisher may find no route yet: again
            send()
            try:
                return heard.get(timeout=5.0)
            except queue.Empty:
                continue
        return "no answer", None
    finally:
        delattr(owner, method)  # the class's method again


def zenoh_goals(motor: str, position: float) -> Send:
    """A goals message on ``poppy/jr1/goals``; the refusal's kind as the server logs it."""

    def send(s: Surfaces, n: Network) -> Outcome:
        from poppy_core import zenoh_wire

        server = n.servers.zenoh
        payload = zenoh_wire.goals_message({motor: position})
        what, _ = _heard(server, "apply_goals", lambda: n.session.put("poppy/jr1/goals", payload))
        if what != "raised":
            return what, ""
        kind, said = server.last_refusal
        return kind, said

    return send  # type: ignore[return-value]


def _radians(n: Network, motor: str, degrees: float) -> float:
    ros2 = n.servers.ros2
    return ros2.joints.to_joint(motor, degrees) if motor in ros2.joints.frames else degrees


def ros2_command(motor: str, position: float) -> Send:
    """A sensor_msgs/JointState on ``/joint_command``; the refusal's kind as the node reports
    it (its ``Refusal`` event, on /rosout and /diagnostics)."""

    def send(s: Surfaces, n: Network) -> Outcome:
        import numpy as np

        from tests.ros2.test_ros2_node import JOINT_STATE, _joint_command

        message = _joint_command([motor], np.array([_radians(n, motor, position)]))
        return _ros2_outcome(
            n, "command", lambda: n.ros2.publish("/joint_command", JOINT_STATE, message)
        )

    return send  # type: ignore[return-value]


def ros2_trajectory(motor: str, position: float, duration_s: float) -> Send:
    """A trajectory_msgs/JointTrajectory of one point, ``duration_s`` after its start."""

    def send(s: Surfaces, n: Network) -> Outcome:
        from tests.ros2.test_ros2_node import TRAJECTORY, _trajectory

        point = (duration_s, [_radians(n, motor, position)])
        message = _trajectory([motor], [point])
        return _ros2_outcome(
            n, "follow", lambda: n.ros2.publish("/joint_trajectory", TRAJECTORY, message)
        )

    return send  # type: ignore[return-value]


def _ros2_outcome(n: Network, method: str, publish: Callable[[], None]) -> Outcome:
    node = n.servers.ros2
    refusals: list[Any] = []
    node.refusals.listen(refusals.append)
    what, _ = _heard(node.commands, method, publish)
    if what != "raised":
        return what, ""
    assert eventually(lambda: bool(refusals)), "a refusal is reported"
    return refusals[-1].error, refusals[-1].reason


def _ros2_duration(duration: float) -> bool:
    """A duration a builtin_interfaces/Duration holds (whole nanoseconds; no NaN nor inf)."""
    return math.isfinite(duration) and (duration == 0 or abs(duration) >= 1e-9)


# -- the table ----------------------------------------------------------------------------------


def goto_case(name: str, kind: str, position: str, duration: str) -> Case:
    """``m1`` to ``position`` (JSON/URL text) in ``duration`` seconds, on every surface."""
    p, d = float(position), float(duration)
    v1 = f'{{"positions": {{"m1": {_json(p)}}}, "duration_s": {_json(d)}}}'
    pypot = f'{{"position": {_json(p)}, "duration": {_json(d)}}}'
    return Case(
        name,
        kind,
        python=python(lambda r: r.goto_position({"m1": p}, d, wait=False)),
        cli=cli("robot", "goto", f"m1={position}", "--duration", duration),
        rest_v1=rest_v1("POST", "/api/v1/gotos", v1),
        rest_pypot=rest_pypot("POST", "/motors/m1/goto.json", pypot),
        snap=snap(f"/motor/m1/goto/{position}/{duration}"),
        zmq=zmq("set_goto_position_for_motor", motor="m1", position=p, duration=d),
        ros2=ros2_trajectory("m1", p, d) if _ros2_duration(d) else None,
    )


def goal_case(name: str, kind: str, position: str) -> Case:
    """A goal_position write of ``m1`` (the surfaces without a duration: register writes)."""
    p = float(position)

    def set_goal(robot: Any) -> None:
        robot.m1.goal_position = p

    return Case(
        name,
        kind,
        python=python(set_goal),
        rest_v1=rest_v1(
            "PUT", "/api/v1/motors/m1/registers/goal_position", f'{{"value": {_json(p)}}}'
        ),
        rest_pypot=rest_pypot("POST", "/motors/m1/registers/goal_position/value.json", _json(p)),
        ws=ws(f'{{"m1": {{"goal_position": {_json(p)}}}}}'),
        snap=snap(f"/motor/m1/set/goal_position/{position}"),
        zmq=zmq("set_register_value", motor="m1", register="goal_position", value=p),
        zenoh_goals=zenoh_goals("m1", p),
        ros2=ros2_command("m1", p),
    )


def _json(value: float) -> str:
    """JSON text of ``value`` with Python's NaN/Infinity tokens (what a hostile client sends)."""
    return json.dumps(value)


CASES = [
    goto_case("goto-position-nan", "invalid", "nan", "0.2"),
    goto_case("goto-position-inf", "invalid", "inf", "0.2"),
    goto_case("goto-position-huge", "invalid", "1e12", "0.2"),
    goto_case("goto-position-beyond-limit", "clamped", "500", "0"),
    goto_case("goto-position-beyond-negative-limit", "clamped", "-500", "0"),
    goto_case("goto-duration-nan", "invalid", "10", "nan"),
    goto_case("goto-duration-inf", "invalid", "10", "inf"),
    goto_case("goto-duration-negative", "invalid", "10", "-1"),
    goto_case("goto-duration-vanishing", "invalid", "10", "1e-300"),
    goto_case("goto-duration-huge", "invalid", "10", "1e6"),
    goto_case("goto-duration-zero", "accepted", "10", "0"),
    goal_case("goal-nan", "invalid", "nan"),
    goal_case("goal-inf", "invalid", "inf"),
    goal_case("goal-huge", "invalid", "1e12"),
    goal_case("goal-beyond-limit", "clamped", "500"),
    Case(
        "goto-unknown-motor",
        "not_found",
        python=python(lambda r: r.goto_position({"m9": 10}, 0.2, wait=False)),
        cli=cli("robot", "goto", "m9=10", "--duration", "0.2"),
        rest_v1=rest_v1("POST", "/api/v1/gotos", '{"positions": {"m9": 10}, "duration_s": 0.2}'),
        rest_pypot=rest_pypot("POST", "/motors/m9/goto.json", '{"position": 10, "duration": 1}'),
        ws=ws('{"m9": {"goal_position": 10}}'),
        snap=snap("/motor/m9/goto/10/1"),
        zmq=zmq("set_goto_position_for_motor", motor="m9", position=10, duration=1),
        zenoh_goals=zenoh_goals("m9", 10.0),
        ros2=ros2_trajectory("m9", 10.0, 1.0),
    ),
    Case(
        "goal-unknown-motor",
        "not_found",
        ros2=ros2_command("m9", 10.0),
    ),
    Case(
        "goto-unknown-control",
        "invalid",
        python=python(lambda r: r.goto_position({"m1": 10}, 0.2, control="linear", wait=False)),
        cli=cli("robot", "goto", "m1=10", "--trajectory", "linear"),
        rest_v1=rest_v1(
            "POST",
            "/api/v1/gotos",
            '{"positions": {"m1": 10}, "duration_s": 0.2, "control": "linear"}',
        ),
        zmq=zmq(
            "set_goto_positions_for_motors",
            motors=["m1"],
            positions=[10],
            duration=0.2,
            control="linear",
        ),
    ),
    Case(
        "unknown-group",
        "not_found",
        python=python(lambda r: r.group("nope")),
        rest_v1=rest_v1("GET", "/api/v1/groups/nope"),
        rest_pypot=rest_pypot("GET", "/motors/nope/list.json"),
        zmq=zmq("get_motors_list", alias="nope"),
    ),
    Case(
        "unknown-primitive",
        "not_found",
        python=python(lambda r: attached_primitive(r, "nope")),
        cli=cli("primitive", "run", "nope", "--duration", "0.2"),
        rest_v1=rest_v1("POST", "/api/v1/primitives/nope/start"),
        rest_pypot=rest_pypot("GET", "/primitives/nope/start.json"),
        snap=snap("/primitive/nope/start"),
        zmq=zmq("start_primitive", primitive="nope"),
    ),
    Case(
        "unknown-move",
        "not_found",
        python=python(lambda r: load_move("nope")),
        cli=cli("play", "nope"),
        rest_v1=rest_v1("GET", "/api/v1/moves/nope"),
        rest_pypot=rest_pypot("GET", "/records/nope/value.json"),
        snap=snap("/primitive/MovePlayer/nope/start"),
        zmq=zmq("start_move_player", move_name="nope"),
    ),
]

PAIRS = [
    pytest.param(case, surface, id=f"{case.name}-{surface}")
    for case in CASES
    for surface in SURFACES
    if getattr(case, surface) is not None
]


def _reset_goal(robot: Any) -> None:
    # stiff: the v1 API refuses a goal to a compliant motor (409) before any argument rule
    robot.compliant = False
    # no owner: a goal stream or a trajectory of the case before would own m1 (409); each
    # surface is asked about the argument alone (ownership: tests/server/test_motor_leases.py)
    motor_leases(robot).release_all()
    robot.m1.goal_position = 0.0
    assert eventually(lambda: abs(robot.m1.goal_position) < 1.0)


@pytest.mark.parametrize(("case", "surface"), PAIRS)
def test_every_surface_gives_the_same_kind(
    surfaces: Surfaces,  # noqa: F811  (the fixture imported above)
    request: pytest.FixtureRequest,
    case: Case,
    surface: str,
) -> None:
    """The same argument: the same kind of refusal (or the same clamp) on every surface."""
    robot = surfaces.robot
    _reset_goal(robot)
    send: Any = getattr(case, surface)
    if surface in NETWORK:
        network: Network = request.getfixturevalue("network")
        kind, said = send(surfaces, network)
    else:
        kind, said = send(surfaces)
    if case.kind != "clamped":
        assert kind == case.kind, f"{case.name} on {surface}: {kind}: {said}"
        return
    assert kind == "accepted", f"{case.name} on {surface}: {kind}: {said}"
    limit = -LIMIT if "negative" in case.name else LIMIT
    if surface == "cli":  # its own virtual robot: the answer says where the motor went
        assert f"(goal {limit:g}°)" in said, said
        return
    # the same clamp: the motor aims at its limit (one register step from it)
    assert eventually(lambda: abs(robot.m1.goal_position - limit) < 0.5), robot.m1.goal_position
    if surface in ("rest_v1", "zenoh_api") and case.name.startswith("goto"):
        assert json.loads(said)["positions"] == {"m1": limit}  # the answer says the clamp


COMPLIANT_GOAL: dict[str, Any] = {
    "rest_v1": rest_v1("PUT", "/api/v1/motors/m1/registers/goal_position", '{"value": 10}'),
    "zenoh_goals": zenoh_goals("m1", 10.0),
    "ros2": ros2_command("m1", 10.0),
}
"""A goal to a compliant motor on poppy's own surfaces (pypot's keep pypot's answer)."""


@pytest.mark.parametrize("surface", sorted(COMPLIANT_GOAL))
def test_a_goal_to_a_compliant_motor_is_refused_on_our_surfaces(
    surfaces: Surfaces,  # noqa: F811  (the fixture imported above)
    request: pytest.FixtureRequest,
    surface: str,
) -> None:
    """The service's one rule: a compliant motor would not move, so the goal is a conflict
    (v1's 409, the Zenoh stream's counted refusal, the ROS 2 node's Refusal), nothing set."""
    robot = surfaces.robot
    _reset_goal(robot)
    robot.m1.compliant = True
    try:
        send: Any = COMPLIANT_GOAL[surface]
        if surface in NETWORK:
            kind, said = send(surfaces, request.getfixturevalue("network"))
        else:
            kind, said = send(surfaces)
        assert kind == "conflict", f"{surface}: {kind}: {said}"
        assert "compliant" in said, said
        assert abs(robot.m1.goal_position) < 1.0
    finally:
        robot.m1.compliant = False
