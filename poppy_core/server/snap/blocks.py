"""Snap! XML generated for the robot served: the Poppy blocks library (EN, FR) and example projects.

Every document is a Snap! project (``<project>``, the format Snap! opens from
``snap.html#open:URL`` and from a file): global custom blocks calling the Snap! routes with
``reportURL``, two global variables ``host`` and ``port`` holding the server's address, and, for
the examples, scripts using the blocks. Built with ``xml.etree`` so the text is always
well-formed. The blocks are poppy's own (``catalog.py``), not copies of pypot's files.
"""

from __future__ import annotations

import re
import socket
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from poppy_core.server.snap.catalog import BLOCKS, Block, Input

APP = "Snap! 9, https://snap.berkeley.edu"
LANGS = ("en", "fr")
PLACEHOLDER = re.compile(r"\{(\w+)\}")
LABEL_INPUT = re.compile(r"%'(\w+)'")
SELF_CHECK = ("127.0.0.1", "localhost")

E = ET.Element


def sub(parent: ET.Element, tag: str, text: str | None = None, **attrs: str) -> ET.Element:
    """A child element with optional text."""
    child = ET.SubElement(parent, tag, attrs)
    if text is not None:
        child.text = text
    return child


def lit(text: str) -> ET.Element:
    """A literal slot ``<l>text</l>``."""
    element = E("l")
    element.text = text
    return element


def var(name: str) -> ET.Element:
    """A variable getter."""
    return E("block", var=name)


def prim(selector: str, *args: ET.Element) -> ET.Element:
    """A primitive block with its argument elements."""
    element = E("block", s=selector)
    element.extend(args)
    return element


def listed(*items: ET.Element) -> ET.Element:
    """A variadic ``<list>`` of slots."""
    element = E("list")
    element.extend(items)
    return element


def script(*blocks: ET.Element, **attrs: str) -> ET.Element:
    """A ``<script>`` of blocks."""
    element = E("script", attrs)
    element.extend(blocks)
    return element


@dataclass
class RobotFacts:
    """What the blocks' defaults and the examples are filled with: the robot's names."""

    motors: list[str]
    groups: list[str]
    primitives: list[str] = field(default_factory=list)
    properties: dict[str, list[str]] = field(default_factory=dict)
    chains: dict[str, list[float]] = field(default_factory=dict)
    """Chain name -> its tip's present position (m)."""
    cards: list[str] = field(default_factory=list)
    moves: list[str] = field(default_factory=list)

    def default(self, key: str) -> str:
        """The default text of an input (``@...`` keys filled from the robot)."""
        if not key.startswith("@"):
            return key
        first_primitive = next(
            (p for p in self.primitives if self.properties.get(p)), self.primitives[0]
        ) if self.primitives else "dance"  # fmt: skip
        chain = next(iter(self.chains), "chain")
        tip = self.chains.get(chain, [0.0, 0.0, 0.1])
        values = {
            "@motor": self.motors[0],
            "@motors": ";".join(self.motors[:3]),
            "@group": self.groups[0] if self.groups else "motors",
            "@primitive": first_primitive,
            "@property": (self.properties.get(first_primitive) or ["running"])[0],
            "@chain": chain,
            "@card": self.cards[0] if self.cards else "caribou",
            "@move": "my-move",
            "@gotos": ";".join(f"{m}:0:1" for m in self.motors[:3]),
            "@x": f"{tip[0]:.3f}",
            "@y": f"{tip[1]:.3f}",
            "@z": f"{tip[2]:.3f}",
        }
        return values[key]


def label_spec(label: str, inputs: Iterable[Input]) -> str:
    """A use's ``s``: the label with each input as its slot type (``move %n``)."""
    slots = {i.name: i.slot for i in inputs}
    return LABEL_INPUT.sub(lambda m: slots[m.group(1)], label)


def translation(label: str) -> str:
    """A label with ``_`` for each input (Snap!'s block translations)."""
    return LABEL_INPUT.sub("_", label)


def url_expression(template: str, loop_var: str | None = None) -> ET.Element:
    """``http://`` host ``:`` port and the template, joined (inputs as variables)."""
    parts: list[ET.Element] = [lit("http://"), var("host"), lit(":"), var("port")]
    position = 0
    for match in PLACEHOLDER.finditer(template):
        if match.start() > position:
            parts.append(lit(template[position : match.start()]))
        name = match.group(1)
        parts.append(var(loop_var if name == "motor" and loop_var else name))
        position = match.end()
    if position < len(template):
        parts.append(lit(template[position:]))
    return prim("reportJoinWords", listed(*parts))


def show_error() -> ET.Element:
    """Say the answer when it is an error (every error answer starts with ``Error``)."""
    first = prim("reportLetter", lit("1"), var("answer"))
    said = script(prim("bubble", var("answer")))
    return prim("doIf", prim("reportEquals", first, lit("E")), said)


SPLIT = {"names": "/", "values": ";", "numbers": ","}


def block_script(block: Block) -> ET.Element:
    """The definition's script: call the route, read or check the answer."""
    if block.each:
        call = prim("reportURL", url_expression(block.template, "motor"))
        body = [prim("doSetVar", lit("answer"), call), show_error()]
        loop = prim(
            "doForEach",
            lit("motor"),
            prim("reportTextSplit", var(block.each), lit(";")),
            script(*body),
        )
        return script(prim("doDeclareVariables", listed(lit("answer"))), loop)
    call = prim("reportURL", url_expression(block.template))
    if block.kind == "command":
        return script(
            prim("doDeclareVariables", listed(lit("answer"))),
            prim("doSetVar", lit("answer"), call),
            show_error(),
        )
    if block.answer in SPLIT:
        reported = prim("reportTextSplit", call, lit(SPLIT[block.answer]))
    elif block.answer == "bool":
        reported = prim("reportEquals", call, lit("True"))
    else:
        reported = call
    return script(prim("doReport", reported))


def definition(block: Block, lang: str, facts: RobotFacts) -> ET.Element:
    """A ``<block-definition>`` (label in ``lang``, the other language as a translation)."""
    label = block.fr if lang == "fr" else block.en
    other = ("en", block.en) if lang == "fr" else ("fr", block.fr)
    element = E("block-definition", s=label, type=block.kind, category=block.category)
    if block.help_en:
        sub(element, "comment", block.help_en, x="0", y="0", w="200", collapsed="false")
    sub(element, "header")
    sub(element, "code")
    sub(element, "translations", f"{other[0]}:{translation(other[1])}")
    inputs = sub(element, "inputs")
    order = LABEL_INPUT.findall(block.en)
    by_name = {i.name: i for i in block.inputs}
    for name in order:
        item = by_name[name]
        sub(inputs, "input", facts.default(item.default), type=item.slot)
    element.append(block_script(block))
    return element


def host_block(lang: str) -> ET.Element:
    """``set robot host to %'host'``: point every block at another robot."""
    label = "set robot host to %'address'"
    if lang == "fr":
        label = "définir l'hôte du robot à %'address'"
    element = E("block-definition", s=label, type="command", category="variables")
    sub(element, "header")
    sub(element, "code")
    inputs = sub(element, "inputs")
    sub(inputs, "input", "127.0.0.1", type="%s")
    element.append(script(prim("doSetVar", lit("host"), var("address"))))
    return element


def use(block: Block, lang: str, *args: str | bool) -> ET.Element:
    """A use of a Poppy block in a script (arguments in label order)."""
    label = block.fr if lang == "fr" else block.en
    element = E("custom-block", s=label_spec(label, block.inputs))
    names = LABEL_INPUT.findall(label)
    english_order = LABEL_INPUT.findall(block.en)
    values = dict(zip(english_order, args, strict=True))
    for name in names:
        value = values[name]
        if isinstance(value, bool):
            slot = E("l")
            sub(slot, "bool", "true" if value else "false")
            element.append(slot)
        else:
            element.append(lit(str(value)))
    return element


BY_KEY = {b.key: b for b in BLOCKS}


def project(
    name: str,
    notes: str,
    host: str,
    port: int,
    lang: str,
    facts: RobotFacts,
    scripts: list[ET.Element] | None = None,
) -> bytes:
    """A Snap! project holding every Poppy block, ``host``/``port``, and the sprite's scripts."""
    root = E("project", name=name, app=APP, version="1")
    sub(root, "notes", notes)
    sub(root, "thumbnail")
    stage = sub(root, "stage", name="Stage", width="480", height="360", costume="0",
                tempo="60", threadsafe="false", lines="round", codify="false",
                inheritance="true", sublistIDs="false", scheduled="false", id="1")  # fmt: skip
    sub(stage, "pentrails")
    sub(sub(stage, "costumes"), "list", struct="atomic")
    sub(sub(stage, "sounds"), "list", struct="atomic")
    sub(stage, "variables")
    sub(stage, "blocks")
    sub(stage, "scripts")
    sprites = sub(stage, "sprites", select="1")
    sprite = sub(sprites, "sprite", name="Poppy", idx="1", x="0", y="0", heading="90",
                 scale="1", volume="100", pan="0", rotation="1", draggable="true",
                 costume="0", color="80,80,80,1", pen="tip", id="2")  # fmt: skip
    sub(sub(sprite, "costumes"), "list", struct="atomic")
    sub(sub(sprite, "sounds"), "list", struct="atomic")
    sub(sprite, "blocks")
    sub(sprite, "variables")
    sprite_scripts = sub(sprite, "scripts")
    for item in scripts or []:
        sprite_scripts.append(item)
    sub(root, "hidden")
    sub(root, "headers")
    sub(root, "code")
    blocks = sub(root, "blocks")
    blocks.append(host_block(lang))
    for block in BLOCKS:
        blocks.append(definition(block, lang, facts))
    variables = sub(root, "variables")
    sub(sub(variables, "variable", name="host"), "l", host)
    sub(sub(variables, "variable", name="port"), "l", str(port))
    ET.indent(root, space=" ")
    return bytes(ET.tostring(root, encoding="utf-8", xml_declaration=False))


# -- example projects ------------------------------------------------------------------------


def _at(y: int, *blocks: ET.Element) -> ET.Element:
    return script(*blocks, x="20", y=str(y))


def _wait(seconds: float) -> ET.Element:
    return prim("doWait", lit(f"{seconds:g}"))


def _say(value: ET.Element) -> ET.Element:
    return prim("bubble", value)


def first_steps(facts: RobotFacts, lang: str) -> list[ET.Element]:
    """Stiffen, light the LEDs, move one motor then several, say the positions."""
    motors = ";".join(facts.motors)
    first = facts.motors[0]
    b = BY_KEY
    return [
        _at(
            20,
            prim("receiveGo"),
            use(b["compliant"], lang, motors, False),
            use(b["led"], lang, motors, "green"),
            use(b["goto"], lang, motors, "0", "2"),
            _wait(2),
            use(b["goto"], lang, first, "30", "1"),
            _wait(1),
            use(b["goto"], lang, first, "-30", "1"),
            _wait(1),
            _say(use(b["positions"], lang)),
            use(b["led"], lang, motors, "off"),
        ),
        _at(360, prim("receiveKey", lit("space")), use(b["compliant"], lang, motors, True)),
    ]


def record_replay(facts: RobotFacts, lang: str) -> list[ET.Element]:
    """Record a move by hand, then play it forwards, twice as fast, and backwards."""
    motors = ";".join(facts.motors[:3])
    b = BY_KEY
    return [
        _at(
            20,
            prim("receiveGo"),
            use(b["compliant"], lang, motors, True),
            _say(lit("Move me! 5 s" if lang == "en" else "Bouge-moi ! 5 s")),
            use(b["record"], lang, "my-move", motors),
            _wait(5),
            use(b["save"], lang, "my-move"),
            use(b["compliant"], lang, motors, False),
            prim("doWait", use(b["play"], lang, "my-move", "1")),
            _wait(0.5),
            prim("doWait", use(b["play"], lang, "my-move", "2")),
            _wait(0.5),
            prim("doWait", use(b["play_back"], lang, "my-move", "1")),
            _say(use(b["moves"], lang)),
        ),
        _at(420, prim("receiveKey", lit("space")), use(b["stop_move"], lang, "my-move")),
    ]


def ik_drawing(facts: RobotFacts, lang: str) -> list[ET.Element]:
    """Draw a square with the tip of the first chain, 2 cm a side, around its present tip."""
    chain = next(iter(facts.chains), "chain")
    x, y, z = facts.chains.get(chain, [0.0, 0.0, 0.1])
    motors = ";".join(facts.motors)
    b = BY_KEY
    side = 0.01
    corners = [(x - side, y - side), (x + side, y - side), (x + side, y + side)]
    corners.append((x - side, y + side))
    steps: list[ET.Element] = []
    for cx, cy in corners:
        steps.append(use(b["ik_goto"], lang, chain, f"{cx:.3f}", f"{cy:.3f}", f"{z:.3f}", "1"))
        steps.append(_wait(1.2))
    loop = prim("doRepeat", lit("2"), script(*steps))
    return [
        _at(
            20,
            prim("receiveGo"),
            use(b["compliant"], lang, motors, False),
            loop,
            _say(use(b["tip"], lang, chain)),
        )
    ]


EXAMPLES: dict[str, tuple[str, Callable[[RobotFacts, str], list[ET.Element]]]] = {
    "first-steps": ("First steps: stiffen, LEDs, gotos, positions.", first_steps),
    "record-replay": ("Record a move by hand, play it forwards, at 2x, backwards.", record_replay),
    "ik-drawing": ("Draw a square with the tip of the arm (inverse kinematics).", ik_drawing),
}


def project_names() -> list[str]:
    """Every project ``/snap/<name>`` serves: the blocks in each language and the examples."""
    names = ["poppy-blocks", "poppy-blocks-fr"]
    for name in EXAMPLES:
        names += [name, f"{name}-fr"]
    return names


def document(name: str, facts: RobotFacts, host: str, port: int) -> bytes | None:
    """The project ``name`` (``-fr``: in French), or None."""
    lang = "fr" if name.endswith("-fr") else "en"
    base = name.removesuffix("-fr")
    if base == "poppy-blocks":
        notes = "Poppy blocks generated by poppy for this robot."
        return project(name, notes, host, port, lang, facts)
    if base not in EXAMPLES:
        return None
    notes, build = EXAMPLES[base]
    return project(name, notes, host, port, lang, facts, build(facts, lang))


def local_address(server: tuple[str, int] | None, host: str) -> str:
    """The IP a client reached this server at (``/ip/``), else this machine's main address.

    Finding the main address connects a UDP socket (which sends nothing) to a documentation
    address (TEST-NET-1), so no packet leaves the machine.
    """
    if server and server[0] not in ("", "0.0.0.0", "::"):
        return server[0]
    if host not in ("", "0.0.0.0", "::"):
        return host
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            sock.connect(("192.0.2.1", 9))
            return str(sock.getsockname()[0])
    except OSError:
        return "127.0.0.1"


class SnapSite:
    """The documents of one Snap! server: blocks and projects with its address filled in.

    Args:
        facts: a function giving the robot's names now (moves and primitives change).
        host: the address the server listens on.
        port: its port.
    """

    def __init__(self, facts: Callable[[], RobotFacts], host: str, port: int) -> None:
        self.facts = facts
        self.host = host
        self.port = port

    def _where(self, host_header: str | None) -> tuple[str, int]:
        """The host and port to write in a document: as the client reached the server."""
        if host_header:
            name, sep, port = host_header.rpartition(":")
            if sep and port.isdigit() and "]" not in port:
                return name.strip("[]"), int(port)
            return host_header.strip("[]"), self.port
        return local_address(None, self.host), self.port

    def address(self, server: Any) -> str:
        """``/ip/``."""
        return local_address(server, self.host)

    def blocks(self, host_header: str | None = None, lang: str = "en") -> bytes:
        """The Poppy blocks library."""
        name = "poppy-blocks-fr" if lang == "fr" else "poppy-blocks"
        body = self.project(name, host_header)
        assert body is not None
        return body

    def project(self, name: str, host_header: str | None = None) -> bytes | None:
        """A project by name, or None."""
        host, port = self._where(host_header)
        return document(name, self.facts(), host, port)

    @staticmethod
    def project_names() -> list[str]:
        """The projects served under ``/snap/``."""
        return project_names()
