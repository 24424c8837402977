"""Snap! project XML read for the tests: custom blocks, their input menus and the URLs they build.

A Poppy block calls the robot with Snap!'s ``reportURL`` on a text joined from pieces
(``reportJoinWords`` of literals ``<l>``, variables ``<block var=…>``, other custom blocks such as
"$robot robot URL", and "combine with … items of …" folding a list with a joining ring). This
module finds every ``reportURL`` of every block definition and evaluates its text for given
variables, as Snap! would (Snap!'s XML: ``src/store.js`` of jmoenig/Snap).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

SPEC_SLOT = re.compile(r"%'([^']*)'")
CALL_SLOT = re.compile(r"%[^\s]+")
URL_SPECS = ("$robot robot URL", "$robot URL du robot")
"""The blocks answering the robot's ``host:port`` (English, French): evaluated, never a name."""


class Unbound(LookupError):
    """A variable or a block the evaluation was not given."""


def shape(spec: str) -> str:
    """A block's spec with its slots as ``%`` (a definition's ``%'name'`` = a call's ``%txt``)."""
    return CALL_SLOT.sub("%", SPEC_SLOT.sub("%", spec))


@dataclass
class UrlBlock:
    """A custom block definition that calls ``reportURL``."""

    file: str
    spec: str
    element: ET.Element
    inputs: dict[str, ET.Element] = field(default_factory=dict)
    urls: list[ET.Element] = field(default_factory=list)
    """The expressions the URLs are built from (``reportURL``'s argument)."""

    def options(self, name: str) -> list[str]:
        """Input ``name``'s menu values (``label=value`` gives ``value``), else its default."""
        slot = self.inputs[name]
        menu = slot.find("options")
        if menu is None or not (menu.text or "").strip():
            return [(slot.text or "").strip()]
        return [line.split("=", 1)[-1].strip() for line in menu.text.splitlines() if line.strip()]

    def locals(self, given: Mapping[str, Any], project: Project) -> dict[str, Any]:
        """``given`` plus the block's ``set var to …`` whose value needs nothing else (lists)."""
        env = dict(given)
        for step in self.element.iter("block"):
            if step.get("s") != "doSetVar" or len(step) < 2:
                continue
            name = (step[0].text or "").strip()
            if name in env:
                continue
            try:
                value = project.evaluate(step[1], env)
            except (Unbound, ValueError, IndexError):
                continue
            if isinstance(value, list) and value:  # a constant list (an empty one gets filled)
                env[name] = value
        return env


class Project:
    """The custom blocks of one Snap! XML document."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.root = ET.parse(path).getroot()
        self.definitions: dict[str, ET.Element] = {}
        for definition in self.root.iter("block-definition"):
            self.definitions.setdefault(shape(definition.get("s", "")), definition)
        self.symbolic = False

    def url_blocks(self) -> Iterator[UrlBlock]:
        """Every block definition holding a ``reportURL``, with its inputs by name."""
        for definition in self.definitions.values():
            urls = [b[0] for b in definition.iter("block") if b.get("s") == "reportURL" and len(b)]
            if not urls:
                continue
            spec = definition.get("s", "")
            names = SPEC_SLOT.findall(spec)
            slots = definition.find("inputs")
            inputs = list(slots) if slots is not None else []
            yield UrlBlock(
                self.path.name, spec, definition, dict(zip(names, inputs, strict=False)), urls
            )

    def evaluate(self, node: ET.Element, env: Mapping[str, Any]) -> Any:
        """The value of expression ``node`` for variables ``env`` (a text, a number or a list)."""
        if node.tag == "l":
            option = node.find("option")
            return (option.text if option is not None else node.text) or ""
        if node.tag == "list":
            return [self.evaluate(child, env) for child in node]
        var = node.get("var")
        if node.tag == "block" and var is not None:
            if var not in env:
                if self.symbolic:
                    return "{" + var + "}"
                raise Unbound(var)
            return env[var]
        selector = node.get("s", "")
        handler = self._primitives().get(selector) if node.tag == "block" else None
        if handler is not None:
            return handler(node, env)
        if node.tag == "custom-block":
            return self._custom(node, env)
        raise Unbound(f"<{node.tag} s={selector!r}>")

    def _primitives(self) -> dict[str, Callable[[ET.Element, Mapping[str, Any]], Any]]:
        return {
            "reportJoinWords": lambda n, env: "".join(
                _text(self.evaluate(c, env)) for c in _items(n)
            ),
            "reportNewList": lambda n, env: [self.evaluate(c, env) for c in _items(n)],
            "reportListItem": self._list_item,
        }

    def _list_item(self, node: ET.Element, env: Mapping[str, Any]) -> Any:
        index, items = (self.evaluate(child, env) for child in node[:2])
        try:
            return items[int(index) - 1]
        except (ValueError, IndexError, TypeError):
            if self.symbolic:
                return "{keyword}"
            raise

    def _custom(self, node: ET.Element, env: Mapping[str, Any]) -> Any:
        spec = node.get("s", "")
        args = [child for child in node if child.tag != "comment"]
        if spec == "combine with %repRing items of %l":
            return self._combine(args[0], self.evaluate(args[1], env), env)
        if spec == "index of %s in %l":
            item, items = (self.evaluate(a, env) for a in args[:2])
            if item not in items and self.symbolic:
                return "{index}"
            return items.index(item) + 1
        if spec in env:  # a reporter the caller answers ("$robot all motors")
            return env[spec]
        if self.symbolic and spec not in URL_SPECS:
            return "{" + spec + "}"
        definition = self.definitions.get(shape(spec))
        script = definition.find("script") if definition is not None else None
        if (
            script is not None
            and not args
            and len(script) == 1
            and script[0].get("s") == "doReport"
        ):
            return self.evaluate(script[0][0], env)  # "$robot robot URL": host:port
        raise Unbound(spec)

    def _combine(self, ring: ET.Element, items: Any, env: Mapping[str, Any]) -> Any:
        """Snap!'s "combine": fold the list with the ring's reporter (``#1``, ``#2``)."""
        if not isinstance(items, list):
            items = [items]
        body = ring.find("autolambda")
        if body is None or not items:
            return ""
        result = items[0]
        for item in items[1:]:
            result = self.evaluate(body[0], {**env, "#1": result, "#2": item})
        return result

    def template(self, node: ET.Element, env: Mapping[str, Any]) -> str:
        """The URL's shape: every variable not in ``env`` written ``{name}``."""
        self.symbolic = True
        try:
            return _text(self.evaluate(node, env))
        finally:
            self.symbolic = False


def _items(node: ET.Element) -> list[ET.Element]:
    found = node.find("list")
    return list(found) if found is not None else []


def _text(value: Any) -> str:
    if isinstance(value, list):
        return " ".join(_text(v) for v in value)
    return str(value)
