"""pypot's own Snap! blocks and example projects replayed on poppy's Snap! server (issue 23).

Every URL that a block of pypot 5.0.2's ``pypot-snap-blocks.xml``, ``poppy-demo-project.xml``,
``blocs de base Poppy_FR.xml`` and ``poppy-base_demo_FR.xml`` builds is read out of the XML
(``tests/helpers/snap_xml.py`` evaluates the joins as Snap! does), filled with the values the
block's menus offer (and the robot's names where the input is free), sent to a served virtual
Ergo Jr, and the robot's state checked after each. A block URL that no case covers fails the
test: a new block of pypot's is not silently left out.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import pytest

from poppy_core import from_profile
from poppy_core.motion import list_moves, load_move
from poppy_core.robot import Robot
from poppy_core.server.snap import SnapServer, start_snap_server
from tests.helpers import pypot_files
from tests.helpers.pypot_files import snap_project_files
from tests.helpers.snap_xml import Project, UrlBlock
from tests.helpers.waiting import http_timeout
from tests.server.snap_helpers import near, wait_until

HOST = "127.0.0.1"
NOT_THIS_SERVER = {"{host}/services.php?python=restart", "{host}/reset"}
"""pypot's "reset robot" also calls the Raspberry Pi's web page (port 80), not the Snap! server."""

# the menu of pypot's "set LED" block (pypot-snap-blocks.xml): every XL-320 colour
COLOURS = ("off", "red", "green", "yellow", "blue", "pink", "cyan", "white")
REGISTER_VALUES = {
    # the values pypot's blocks send: "set motor(s) compliant/stiff" sends 1/0
    "compliant": (("1", True), ("True", True), ("0", False), ("False", False), ("false", False)),
    "goal_position": (("20", 20.0), ("-15.5", -15.5)),
    "moving_speed": (("100", 100.0),),
    "torque_limit": (("80", 80.0),),
    "led": tuple((c, c) for c in COLOURS),
}
FRENCH_ACTIONS = {"démarrer": "start", "arrêter": "stop", "pause": "pause", "recommencer": "resume"}
LIFECYCLE = ("start", "pause", "resume", "stop")


@dataclass
class Call:
    """One URL to send: the block's variables, and the check of the answer and the robot."""

    env: dict[str, Any]
    check: Callable[[httpx.Response], None]


@dataclass
class Replay:
    """The served robot and what the replay keeps between calls (moves being recorded/saved)."""

    robot: Robot
    server: SnapServer
    http: httpx.Client
    recording: dict[str, list[str]]
    saved: list[str]
    counter: int = 0

    @property
    def motors(self) -> list[str]:
        return [m.name for m in self.robot.motors]

    def new_move(self, tag: str) -> str:
        self.counter += 1
        return f"pypot_{tag}_{self.counter}"


Cases = Callable[[Replay, UrlBlock], Iterator[Call]]


def _ok(expected: str | None = None) -> Callable[[httpx.Response], None]:
    def check(answer: httpx.Response) -> None:
        if expected is not None:
            assert answer.text == expected

    return check


def motor_sets(replay: Replay) -> list[list[str]]:
    return [["m1"], replay.motors]


def groups(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    service = replay.server.service
    for alias in [*service.groups(), "motors"]:
        yield Call({"alias": alias}, _ok("/".join(service.group(alias))))


def positions(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    def check(answer: httpx.Response) -> None:
        values = [float(v) for v in answer.text.split(";")]
        assert len(values) == len(replay.motors)

    yield Call({}, check)


def get_register(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    for register in block.options("register"):
        for motors in motor_sets(replay):

            def check(
                answer: httpx.Response, register: str = register, n: int = len(motors)
            ) -> None:
                values = answer.text.split(";")
                assert len(values) == n
                if register == "led":
                    assert set(values) <= set(COLOURS) | {"off"}
                else:
                    assert all(float(v) == float(v) for v in values)  # numbers, not None

            yield Call({"register": register, "motors": motors}, check)


def set_register(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    registers = block.options("register")
    assert "compliant" in registers
    # stiff first: a goal position is then followed
    for register in ["compliant", *[r for r in registers if r != "compliant"]]:
        for text, value in REGISTER_VALUES[register]:
            for motors in motor_sets(replay):

                def check(
                    answer: httpx.Response,
                    register: str = register,
                    value: Any = value,
                    motors: list[str] = motors,
                ) -> None:
                    assert answer.text == "Done!"
                    for name in motors:
                        now = getattr(replay.robot.motors_of([name])[0], register)
                        if isinstance(value, float):
                            assert now == pytest.approx(value, abs=0.5), (name, register)
                        else:
                            assert now == value, (name, register)
                    if register == "goal_position":
                        motor = replay.robot.motors_of([motors[0]])[0]
                        assert wait_until(lambda: near(motor.present_position, value))

                yield Call({"register": register, "motors": motors, "value": text}, check)
    # the robot stays stiff for what follows
    yield Call({"register": "compliant", "motors": replay.motors, "value": "0"}, _ok("Done!"))


def goto(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    duration = block.options("duration")[0]
    default = float(block.options("position")[0])
    targets = [
        ({name: default for name in replay.motors}, duration),  # the block's defaults
        ({"m1": 30.0, "m2": -20.0}, "0.5"),
    ]
    for wanted, seconds in targets:

        def check(answer: httpx.Response, wanted: dict[str, float] = wanted) -> None:
            assert answer.text == "Done!"
            for name, target in wanted.items():
                motor = replay.robot.motors_of([name])[0]
                assert wait_until(lambda m=motor, t=target: near(m.present_position, t)), name

        mot_pos = [f"{name}:{target:g}" for name, target in wanted.items()]
        yield Call({"mot_pos": mot_pos, "duration": seconds}, check)


def plain(expected: Callable[[Replay], str]) -> Cases:
    def cases(replay: Replay, block: UrlBlock) -> Iterator[Call]:
        yield Call({}, lambda answer: _ok(expected(replay))(answer))

    return cases


def record(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    for motors in (["m1", "m2", "m3"], replay.motors):
        move = replay.new_move(block.file[:5].replace(" ", "_"))

        def check(answer: httpx.Response, move: str = move, motors: list[str] = motors) -> None:
            assert answer.text == "Done!"
            assert move in replay.server.service.moves.recording()
            replay.recording[move] = motors

        # the list variable, or the "all motors" reporter the URL calls (English, French)
        env = {"record_name": move, "motors_list": motors, "complete motor list": motors}
        env |= {"$robot all motors": motors, "$robot noms de tous les moteurs": motors}
        yield Call(env, check)


def recorded_motors(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    for move, motors in replay.recording.items():
        yield Call({"record_name": move}, _ok("/".join(motors)))


def save(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    if replay.recording:  # a motion to record: the plays are checked against its ends
        target = 25.0 if replay.robot.m1.present_position < 0 else -25.0
        replay.robot.goto_position({"m1": target}, 0.4, wait=True)
    for move in list(replay.recording):

        def check(answer: httpx.Response, move: str = move) -> None:
            assert answer.text == "Done!"
            assert move in [entry.name for entry in list_moves()]
            del replay.recording[move]
            replay.saved.append(move)

        yield Call({"record_name": move}, check)


def play(backwards: bool) -> Cases:
    def cases(replay: Replay, block: UrlBlock) -> Iterator[Call]:
        moves = replay.server.service.moves
        for move in replay.saved[-1:]:
            for speed in (block.options("speed")[0], "2"):

                def check(answer: httpx.Response, move: str = move, speed: str = speed) -> None:
                    full = load_move(move).duration_s
                    assert float(answer.text) == pytest.approx(full / float(speed), abs=0.01)
                    assert wait_until(lambda: move not in moves.playing(), timeout_s=30)
                    frames = load_move(move)
                    last = frames.frame(0 if backwards else len(frames) - 1)
                    for name, position in last.items():
                        motor = replay.robot.motors_of([name])[0]
                        assert wait_until(
                            lambda m=motor, p=position: near(m.present_position, p, 3)
                        )

                yield Call({"record_name": move, "speed": speed}, check)

    return cases


def stop_move(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    moves = replay.server.service.moves
    for move in replay.saved[-1:]:

        def start_then_check(answer: httpx.Response, move: str = move) -> None:
            assert answer.text == "Done!"
            assert move not in moves.playing()

        moves.play(move, 0.1, False)  # a long play, stopped by the block
        yield Call({"record_name": move}, start_then_check)


def behaviour_states(replay: Replay, action: str) -> Callable[[httpx.Response], None]:
    primitive = replay.server.service.primitive("dance")

    def check(answer: httpx.Response) -> None:
        assert answer.text == "Done!"
        state = primitive.describe()["state"]
        if action == "stop":
            assert not primitive.is_alive()
        elif action == "pause":
            assert state == "paused"
        else:
            assert primitive.is_alive() and state != "paused"

    return check


def control(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    actions = block.options("action")
    if set(actions) == set(FRENCH_ACTIONS):
        by_action = {english: french for french, english in FRENCH_ACTIONS.items()}
    else:
        assert set(actions) == set(LIFECYCLE)
        by_action = {action: action for action in LIFECYCLE}
    for action in LIFECYCLE:
        env = {"action": by_action[action], "primitive": "dance"}
        yield Call(env, behaviour_states(replay, action))


def behaviour_lists(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    service = replay.server.service
    for what in block.options("input"):
        for primitive in service.primitives():
            names = (
                service.method_names(primitive)
                if what == "methodes"
                else service.property_names(primitive)
            )
            yield Call({"input": what, "primitive": primitive}, _ok("/".join(names)))


def cards(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    for card in block.options("card"):
        yield Call({"card": card}, _ok("False"))  # nothing in view of the virtual camera


def address(replay: Replay, block: UrlBlock) -> Iterator[Call]:
    # "ping http://" and "http://" get the robot's URL from "test connection": the route list
    def check(answer: httpx.Response) -> None:
        assert answer.text.startswith("poppy's Snap! server")

    base = f"{HOST}:{replay.server.port}"
    yield Call({"url": base, "input": base}, check)


CASES: dict[str, Cases] = {
    "/motors/alias": plain(lambda r: "/".join(r.server.service.groups())),
    "/motors/{alias}": groups,
    "/motors/get/positions": positions,
    "/motors/{motors}/get/{register}": get_register,
    "/motors/set/registers/{motors}:{register}:{value}": set_register,
    "/motors/set/goto/{mot_pos}:{duration}": goto,
    "/primitives": plain(lambda r: "/".join(r.server.service.primitives())),
    "/primitives/running": plain(lambda r: "/".join(r.server.service.running_primitives())),
    "/primitive/{primitive}/{action}": control,
    "/primitive/{primitive}/{keyword}": control,
    "/primitive/{primitive}/{input}": behaviour_lists,
    "/primitive/MoveRecorder/{record_name}/start/{motors_list}": record,
    "/primitive/MoveRecorder/{record_name}/start/{complete motor list}": record,
    "/primitive/MoveRecorder/{record_name}/start/{$robot all motors}": record,
    "/primitive/MoveRecorder/{record_name}/start/{$robot noms de tous les moteurs}": record,
    "/primitive/MoveRecorder/{record_name}/get_motors": recorded_motors,
    "/primitive/MoveRecorder/{record_name}/stop": save,
    "/primitive/MovePlayer": plain(lambda r: "/".join(r.server.service.moves.names())),
    "/primitive/MovePlayer/{record_name}/start/{speed}": play(backwards=False),
    "/primitive/MovePlayer/{record_name}/start/{speed}/backwards": play(backwards=True),
    "/primitive/MovePlayer/{record_name}/stop": stop_move,
    "/detect/{card}": cards,
    "/reset-simulation": plain(lambda r: "Done!"),
    "/ip/": plain(lambda r: HOST),
    "{url}": address,
    "{input}": address,
}
"""Each URL shape (after the robot's ``host:port``) and the calls replaying it, in this order."""


def url_shapes() -> dict[str, list[tuple[Project, UrlBlock, Any]]]:
    """Every URL shape of pypot's files -> the (project, block, URL expression) building it."""
    shapes: dict[str, list[tuple[Project, UrlBlock, Any]]] = {}
    for path in snap_project_files().values():
        project = Project(path)
        for block in project.url_blocks():
            env = block.locals({"host": "{host}", "port": "{port}"}, project)
            for url in block.urls:
                shape = project.template(url, env).removeprefix("{host}:{port}")
                shapes.setdefault(shape, []).append((project, block, url))
    return shapes


@pytest.fixture(scope="module")
def replay(moves_folder: str) -> Iterator[Replay]:
    """A virtual Ergo Jr (with its behaviours) served by the Snap! server on a free port."""
    robot = from_profile("ergo-jr", sim=True)
    server = start_snap_server(robot, port=0)
    try:
        with httpx.Client(
            base_url=f"http://{HOST}:{server.port}", timeout=http_timeout(30.0)
        ) as http:
            yield Replay(robot, server, http, {}, [])
    finally:
        server.stop()
        robot.close()


def test_every_block_url_of_pypots_files_is_replayed() -> None:
    shapes = set(url_shapes())
    assert shapes - NOT_THIS_SERVER == set(CASES), "a block URL with no replay case"


def test_pypots_blocks_and_projects_drive_the_robot(replay: Replay) -> None:
    shapes = url_shapes()
    sent = 0
    for name in snap_project_files():  # each file in turn: its moves are recorded, then played
        for shape, cases in CASES.items():
            for project, block, url in shapes[shape]:
                if project.path.name == name:
                    sent += replay_block(replay, project, block, url, cases)
    assert sent > 200


def replay_block(replay: Replay, project: Project, block: UrlBlock, url: Any, cases: Cases) -> int:
    """Send ``url`` of ``block`` for each of its cases and check each; the number sent."""
    sent = 0
    for call in cases(replay, block):
        env = block.locals({"host": HOST, "port": str(replay.server.port), **call.env}, project)
        target = project.evaluate(url, env)
        answer = replay.http.get(f"http://{target}")  # Snap!'s url block adds http://
        where = f"{project.path.name}: {block.spec} -> {target}"
        assert answer.status_code == 200, f"{where}: {answer.status_code} {answer.text}"
        try:
            call.check(answer)
        except AssertionError as exc:
            raise AssertionError(f"{where}: {answer.text[:200]!r}: {exc}") from exc
        sent += 1
    return sent


@pytest.mark.parametrize("ci", ["true", ""])
def test_without_pypots_files_ci_fails_and_a_desk_skips(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, ci: str
) -> None:
    def offline(target: Path) -> None:
        raise RuntimeError("`pip download --no-deps pypot==5.0.2` failed: no network")

    monkeypatch.setattr(pypot_files, "_in_peers", lambda: None)
    monkeypatch.setattr(pypot_files, "_download", offline)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv("CI", ci)
    outcome = pytest.fail.Exception if ci else pytest.skip.Exception
    with pytest.raises(outcome, match=r"pypot 5\.0\.2's Snap! files are needed .* no network"):
        pypot_files.snap_project_files()
