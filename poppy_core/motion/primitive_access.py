"""A primitive's declared properties and methods, read, set and called by name (REST, CLI)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

from poppy_core.errors import ArgumentError, UnknownNameError
from poppy_core.motion.primitive_values import convert_value

_PLURALS = {"property": "properties", "method": "methods"}


class Exposing(Protocol):
    """What these functions need of a primitive: the names it declares."""

    @property
    def properties(self) -> Sequence[str]:
        """Names ``get_property``/``set_property`` expose."""
        ...

    @property
    def methods(self) -> Sequence[str]:
        """Names ``call_method`` may call."""
        ...


def get_property(owner: Exposing, name: str) -> Any:
    """The value of declared property ``name``.

    Raises:
        UnknownNameError: ``name`` is not in ``properties`` (``kind`` ``"property"``).
    """
    check_name(owner, name, owner.properties, "property")
    return getattr(owner, name)


def set_property(owner: Exposing, name: str, value: Any) -> None:
    """Set declared property ``name``, converted to the type of its present value.

    Text is parsed (``"0.5"``, ``"true"``, ``"m1,m2"``), so command-line and JSON values work.

    Raises:
        UnknownNameError: an unknown property (``kind`` ``"property"``).
        ArgumentError: a value of the wrong type, or one the primitive refuses.
    """
    check_name(owner, name, owner.properties, "property")
    converted = convert_value(name, getattr(owner, name), value)
    try:
        setattr(owner, name, converted)
    except (TypeError, ValueError) as exc:
        raise ArgumentError(f"property {name}: {exc}", field=name, value=value) from None


def property_values(owner: Exposing) -> dict[str, Any]:
    """Every declared property and its value."""
    return {name: getattr(owner, name) for name in owner.properties}


def call_method(owner: Exposing, name: str, *args: Any) -> Any:
    """Call declared method ``name`` with ``args`` and return its result.

    Raises:
        UnknownNameError: ``name`` is not in ``methods`` (``kind`` ``"method"``).
    """
    check_name(owner, name, owner.methods, "method")
    return getattr(owner, name)(*args)


def check_name(owner: object, name: str, known: Sequence[str], kind: str) -> None:
    """Raises UnknownNameError: ``name`` is not among the ``known`` names of that ``kind``."""
    if name not in known:
        listed = ", ".join(known) or "none"
        raise UnknownNameError(
            f"{type(owner).__name__} has no {kind} {name!r} ({_PLURALS[kind]}: {listed})",
            name=str(name),
            known=list(known),
            kind=kind,
        )
