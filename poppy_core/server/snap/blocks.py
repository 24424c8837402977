"""Snap! XML generated for the robot served: the Poppy blocks library (EN, FR) and example projects.

Every document is a Snap! project (``<project>``, the format Snap! opens from
``snap.html#open:URL`` and from a file): global custom blocks calling the Snap! routes with
``reportURL``, two global variables ``host`` and ``port`` holding the server's address, and, for
the examples, scripts using the blocks. Built with ``xml.etree`` so the text is always
well-formed. The blocks are poppy's own (``catalog.py``), not copies of pypot's files.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field
from urllib.parse import quote

from poppy_core.server.snap.catalog import BLOCKS, Input, SnapBlock

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
        first_primitive = (
            next((p for p in self.primitives if self.properties.get(p)), self.primitives[0])
            if self.primitives
            else "dance"
        )
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
            "@moves": "my-move",
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


def add_token(root: ET.Element, token: str) -> None:
    """Append ``?token=...`` to every URL the blocks of ``root`` build."""
    suffix = f"?token={quote(token, safe='')}"
    for joined in root.iter("list"):
        first = joined[0] if len(joined) else None
        if first is not None and first.tag == "l" and first.text == "http://":
            joined.append(lit(suffix))


def show_error() -> ET.Element:
    """Say the answer when it is an error (every error answer starts with ``Error``)."""
    first = prim("reportLetter", lit("1"), var("answer"))
    said = script(prim("bubble", var("answer")))
    return prim("doIf", prim("reportEquals", first, lit("E")), said)


SPLIT = {"names": "/", "values": ";", "numbers": ","}


def block_script(block: SnapBlock) -> ET.Element:
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


def definition(block: SnapBlock, lang: str, facts: RobotFacts) -> ET.Element:
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


def use(block: SnapBlock, lang: str, *args: str | bool) -> ET.Element:
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
    token: str = "",
) -> bytes:
    """A Snap! project holding every Poppy block, ``host``/``port``, and the sprite's scripts.

    With ``token`` (a server started with ``--token``), every URL the blocks call carries it.
    """
    root = E("project", name=name, app=APP, version="1")
    sub(root, "notes", notes)
    sub(root, "thumbnail")
    stage = sub(
        root,
        "stage",
        name="Stage",
        width="480",
        height="360",
        costume="0",
        tempo="60",
        threadsafe="false",
        lines="round",
        codify="false",
        inheritance="true",
        sublistIDs="false",
        scheduled="false",
        id="1",
    )
    sub(stage, "pentrails")
    sub(sub(stage, "costumes"), "list", struct="atomic")
    sub(sub(stage, "sounds"), "list", struct="atomic")
    sub(stage, "variables")
    sub(stage, "blocks")
    sub(stage, "scripts")
    sprites = sub(stage, "sprites", select="1")
    sprite = sub(
        sprites,
        "sprite",
        name="Poppy",
        idx="1",
        x="0",
        y="0",
        heading="90",
        scale="1",
        volume="100",
        pan="0",
        rotation="1",
        draggable="true",
        costume="0",
        color="80,80,80,1",
        pen="tip",
        id="2",
    )
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
    if token:
        add_token(root, token)
    ET.indent(root, space=" ")
    return bytes(ET.tostring(root, encoding="utf-8", xml_declaration=False))
