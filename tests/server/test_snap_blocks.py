"""The Snap! documents poppy generates: well-formed projects whose blocks call served routes."""

from __future__ import annotations

import re
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator

import httpx
import pytest
from starlette.routing import Match

from poppy_core import from_profile
from poppy_core.motion import Move, save_move
from poppy_core.server.snap import robot_facts, start_snap_server
from poppy_core.server.snap.catalog import BLOCKS, SnapBlock
from poppy_core.server.snap.examples import project_names
from poppy_core.server.snap.routing import TextRouter
from tests.helpers.waiting import http_timeout
from tests.server.snap_helpers import Served, near, served_ergo, wait_until


@pytest.fixture(scope="module")
def snap(moves_folder: str) -> Iterator[Served]:
    """A virtual Ergo Jr (with its behaviours and chain) served by the Snap! server."""
    yield from served_ergo()


def url_of(definition: ET.Element) -> str | None:
    """The route template a block definition calls, rebuilt from its XML (inputs as {name})."""
    call = definition.find(".//block[@s='reportURL']/block[@s='reportJoinWords']/list")
    if call is None:
        return None
    parts = []
    for item in call:
        if item.tag == "l":
            parts.append(item.text or "")
        else:
            parts.append("{" + item.attrib["var"] + "}")
    text = "".join(parts)
    assert text.startswith("http://{host}:{port}/")
    return text.removeprefix("http://{host}:{port}")


def served_route(router: TextRouter, path: str) -> str | None:
    """The template of the route ``path`` reaches, or None."""
    found = router.match(path)
    if found:
        return found[0].path
    for route in router.app.routes:  # type: ignore[attr-defined]  # the documents, /ip/
        match, _ = route.matches({"type": "http", "path": path, "method": "GET"})
        if match is Match.FULL:
            return str(route.path)
    return None


@pytest.mark.parametrize("name", project_names())
def test_every_project_is_a_well_formed_snap_project(snap: Served, name: str) -> None:
    _, server, http = snap
    answer = http.get(f"/snap/{name}")
    assert answer.status_code == 200
    root = ET.fromstring(answer.content)
    assert root.tag == "project" and root.get("name") == name
    variables = {v.get("name"): v.findtext("l") for v in root.findall("./variables/variable")}
    assert variables == {"host": "127.0.0.1", "port": str(server.port)}  # as the client reached it
    definitions = root.findall("./blocks/block-definition")
    assert len(definitions) == len(BLOCKS) + 1  # and "set robot host"
    french = name.endswith("-fr")
    labels = {d.get("s") for d in definitions}
    assert {b.fr if french else b.en for b in BLOCKS} <= labels
    router = server.thread.server.config.app.app  # inside the OriginGuard
    assert isinstance(router, TextRouter)
    for definition in definitions:
        template = url_of(definition)
        if template is None:
            continue
        names = re.findall(r"%'(\w+)'", definition.get("s", ""))
        defaults = [i.text or "" for i in definition.findall("./inputs/input")]
        values = {"motor": "m1", **dict(zip(names, defaults, strict=True))}
        sample = template.format(**values)
        assert served_route(router, sample), f"{definition.get('s')}: {template} is not served"
    uses = {u.get("s") for u in root.iter("custom-block")}
    defined = {d.get("s").replace("%'", "%").split("%")[0] for d in definitions}  # type: ignore[union-attr]
    for spec in uses:
        assert spec and spec.split("%")[0] in defined, spec


def test_blocks_xml_is_the_english_library_with_french_translations(snap: Served) -> None:
    http = snap[2]
    root = ET.fromstring(http.get("/snap-blocks.xml").content)
    goto = next(
        d for d in root.iter("block-definition") if d.get("s", "").startswith("move motors")
    )
    assert goto.findtext("translations", "").startswith("fr:tourner les moteurs _ à _")
    defaults = [i.text for i in goto.findall("./inputs/input")]
    assert defaults == ["m1;m2;m3", "0", "1"]  # the served robot's motors


def fill(block: SnapBlock, facts_default: dict[str, str]) -> list[str]:
    """The URLs a block calls with its default inputs (once per motor for ``each`` blocks)."""
    values = {i.name: facts_default[i.name] for i in block.inputs}
    if block.each:
        motors = values[block.each].split(";")
        return [block.template.format(**{**values, "motor": m}) for m in motors]
    return [block.template.format(**values)]


def test_each_block_url_template_is_called_and_answers(snap: Served) -> None:
    _, server, http = snap
    facts = robot_facts(server.service)
    for block in BLOCKS:
        defaults = {i.name: facts.default(i.default) for i in block.inputs}
        for url in fill(block, defaults):
            answer = http.get(url)
            assert answer.status_code == 200, f"{block.key}: {url} -> {answer.text}"
            assert "\n" not in answer.text
            if block.answer == "done":
                assert answer.text == "Done!", f"{block.key}: {url} -> {answer.text}"
            if block.answer == "bool":
                assert answer.text in ("True", "False")
            if block.answer == "number":
                assert float(answer.text) >= 0
        if block.key == "record":
            time.sleep(0.3)  # a few frames before "save"
        if block.key == "primitive":
            http.get(f"/primitive/{defaults['primitive']}/stop")


def test_blocks_follow_the_robot_served(moves_folder: str) -> None:
    with from_profile("torso", sim=True) as robot:
        server = start_snap_server(robot, port=0)
        try:
            xml = httpx.get(
                f"http://127.0.0.1:{server.port}/snap-blocks.xml", timeout=http_timeout(20)
            ).text
        finally:
            server.stop()
    root = ET.fromstring(xml)
    tip = next(
        d for d in root.iter("block-definition") if d.get("s", "").startswith("tip position")
    )
    assert tip.findtext("./inputs/input") == "l_arm_chain"


def test_connection_test_and_motor_index(snap: Served) -> None:
    robot, _, http = snap
    assert http.get("/connected").text == "True"  # the block "robot connected?" reads True
    order = http.get("/motors/motors").text.split("/")
    for number, name in enumerate(order, start=1):
        assert http.get(f"/motor/{name}/index").text == str(number)
        assert robot.motors[number - 1].name == name  # the order of 'positions of all motors'
    missing = http.get("/motor/m9/index")
    assert missing.status_code == 404 and missing.text.startswith("Error: no motor 'm9'")


def record_motion(served: Served, move: str, motor: str, target: float) -> None:
    """Record ``move`` on ``motor`` going from 0° to ``target``, through the Snap! routes."""
    robot, server, http = served
    robot.goto_position({motor: 0.0}, 0.3, wait=True)
    assert http.get(f"/primitive/MoveRecorder/{move}/start/{motor}").text == "Done!"
    robot.goto_position({motor: target}, 0.6, wait=True)
    # the move ends at the target: stopped once the recorder sampled it there (a loaded machine
    # ran the recorder late, and a move stopped at once ended at -23° instead of -30°)
    recorder = server.service.moves._recorders[move]
    assert wait_until(lambda: near(recorder.latest().get(motor, 0.0), target, 1))
    assert http.get(f"/primitive/MoveRecorder/{move}/stop").text == "Done!"


@pytest.fixture(scope="module")
def two_moves(snap: Served) -> Served:
    """``first`` (m1: 0° to 30°) and ``second`` (m2: 0° to -30°) in the move library, and
    ``torso`` driving a motor the Ergo Jr lacks."""
    for motor in snap[0].motors:
        motor.compliant = False
    record_motion(snap, "first", "m1", 30.0)
    record_motion(snap, "second", "m2", -30.0)
    save_move(Move(10.0, ["head_z"], [[0.0], [10.0]]), "torso")
    return snap


def test_moves_play_together_and_in_sequence(two_moves: Served) -> None:
    robot, server, http = two_moves
    moves = server.service.moves
    router = server.thread.server.config.app.app
    assert isinstance(router, TextRouter)
    playlists = router.snap.playlists
    first, second = (moves.load(name).duration_s for name in ("first", "second"))

    def home() -> None:
        robot.goto_position({"m1": 0.0, "m2": 0.0}, 0.3, wait=True)

    # together: both start at once (played slowly, so both are seen playing), both end there
    home()
    answer = http.get("/moves/concurrently/first;second/0.25")
    assert float(answer.text) == pytest.approx(max(first, second) / 0.25, abs=0.01)
    assert wait_until(lambda: {"first", "second"} <= set(moves.playing()))
    assert wait_until(lambda: not moves.playing(), timeout_s=30)
    # each at its move's end (a read may be a sync period old: polled)
    assert wait_until(lambda: near(robot.m1.present_position, 30.0, 3))
    assert wait_until(lambda: near(robot.m2.present_position, -30.0, 3))

    # in sequence: the second starts when the first has ended
    home()
    answer = http.get("/moves/sequentially/first;second/0.5")
    assert float(answer.text) == pytest.approx((first + second) / 0.5, abs=0.01)
    seen: list[tuple[str, ...]] = []

    def second_playing() -> bool:
        seen.append(tuple(moves.playing()))
        return "second" in seen[-1]

    assert wait_until(second_playing, timeout_s=30)
    assert ("first",) in seen and ("first", "second") not in seen  # one after the other
    # the first had reached its end (only the second moves now, and only m2)
    assert wait_until(lambda: near(robot.m1.present_position, 30.0, 3))
    assert wait_until(lambda: not moves.playing() and not playlists.sequences(), timeout_s=30)
    assert wait_until(lambda: near(robot.m2.present_position, -30.0, 3))

    # "stop move" on a move of a sequence ends the sequence
    home()
    http.get("/moves/sequentially/first;second/0.25")
    assert playlists.sequences() == [["first", "second"]]
    assert http.get("/primitive/MovePlayer/first/stop").text == "Done!"
    assert wait_until(lambda: not playlists.sequences())
    assert moves.playing() == []


@pytest.mark.parametrize(
    ("path", "status", "says"),
    [
        ("/moves/concurrently/first;nope/1", 404, "no move 'nope'"),
        ("/moves/sequentially/nope;first/1", 404, "no move 'nope'"),
        ("/moves/sequentially/first/0", 400, "speed must be above 0"),
        ("/moves/concurrently/first/nan", 400, "speed must be a finite number"),
        ("/moves/concurrently/;/1", 400, "no move given"),
        ("/moves/sequentially/.b/1", 400, "not a move name"),
        ("/moves/concurrently/first;torso/1", 400, "drives motors this robot lacks: head_z"),
        ("/moves/sequentially/first;torso/1", 400, "drives motors this robot lacks: head_z"),
    ],
)
def test_playing_several_moves_refuses_before_starting_any(
    two_moves: Served, path: str, status: int, says: str
) -> None:
    _, server, http = two_moves
    assert wait_until(lambda: not server.service.moves.playing())
    answer = http.get(path)
    assert answer.status_code == status and says in answer.text, answer.text
    assert server.service.moves.playing() == []


def test_the_library_has_the_blocks_the_poppy_documentation_lists(snap: Served) -> None:
    """A connection test, a motor's index, moves played together and in sequence (issue 23)."""
    http = snap[2]
    for document, labels in (
        (
            "/snap-blocks.xml",
            (
                "robot connected?",
                "index of motor %'motor'",
                "play moves %'moves' together at speed × %'speed'",
                "play moves %'moves' one after the other at speed × %'speed'",
            ),
        ),
        (
            "/snap/poppy-blocks-fr",
            (
                "robot connecté ?",
                "numéro du moteur %'motor'",
                "jouer les mouvements %'moves' ensemble à la vitesse × %'speed'",
            ),
        ),
    ):
        root = ET.fromstring(http.get(document).content)
        defined = {d.get("s") for d in root.iter("block-definition")}
        assert set(labels) <= defined, document
