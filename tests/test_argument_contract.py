"""One argument/error contract: the same bad arguments (NaN, inf, negative, zero, huge, unknown
names) through the Python API, the CLI, REST (v1 and pypot's routes), the WebSocket, Snap! and
ZMQ give the same KIND of refusal, or the same clamp (docs/rest.md, "Arguments and errors").

Kinds: ``invalid`` (an ``ArgumentError``: 422 on v1, 400 on pypot's routes and Snap!),
``not_found`` (an ``UnknownNameError``: 404), ``accepted`` (the call went through). A goal
beyond the angle limits is ``accepted`` and clamped: the motor aims at the limit. The servers
and the robot are the ones of tests/server/test_hostile_numbers.py (its ``surfaces`` fixture).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pytest
from websockets.sync.client import connect

from poppy_core.errors import ArgumentError, PoppyError, UnknownNameError
from poppy_core.motion import attached_primitive, load_move
from tests.helpers.cli import run_poppy
from tests.helpers.waiting import eventually
from tests.server.conftest import moves_folder  # noqa: F401  (the fixture `surfaces` needs)
from tests.server.test_hostile_numbers import Surfaces, surfaces  # noqa: F401

LIMIT = 150.0
"""The Ergo Jr's m1 angle limit (both ways): where a goal beyond it is clamped."""

Outcome = tuple[str, str]
"""(kind, what the surface said)."""
Send = Callable[[Surfaces], Outcome]

V1_KINDS = {422: "invalid", 400: "invalid", 404: "not_found"}
PYPOT_KINDS = {400: "invalid", 404: "not_found"}


@dataclass(frozen=True)
class Case:
    """One bad (or clamped) argument and how each surface is asked it (None: not on it)."""

    name: str
    kind: str
    python: Send | None = None
    cli: Send | None = None
    rest_v1: Send | None = None
    rest_pypot: Send | None = None
    ws: Send | None = None
    snap: Send | None = None
    zmq: Send | None = None


SURFACES = ("python", "cli", "rest_v1", "rest_pypot", "ws", "snap", "zmq")


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


def rest_v1(method: str, path: str, body: str | None = None) -> Send:
    def send(s: Surfaces) -> Outcome:
        headers = {"Content-Type": "application/json"}
        answer = s.http.request(method, path, content=body, headers=headers)
        return _http_kind(answer.status_code, answer.text, V1_KINDS)

    return send


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
    robot.m1.goal_position = 0.0
    assert eventually(lambda: abs(robot.m1.goal_position) < 1.0)


@pytest.mark.parametrize(("case", "surface"), PAIRS)
def test_every_surface_gives_the_same_kind(
    surfaces: Surfaces,  # noqa: F811  (the fixture imported above)
    case: Case,
    surface: str,
) -> None:
    """The same argument: the same kind of refusal (or the same clamp) on every surface."""
    robot = surfaces.robot
    _reset_goal(robot)
    send: Send = getattr(case, surface)
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
    if surface == "rest_v1" and case.name.startswith("goto"):
        assert json.loads(said)["positions"] == {"m1": limit}  # the answer says the clamp
