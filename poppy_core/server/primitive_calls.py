"""A primitive's properties and methods as the server reads, sets and calls them (JSON values)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from poppy_core.motion import Primitive
from poppy_core.server import values
from poppy_core.server.errors import ApiError

PRIMITIVE_TIP = "the primitives are listed by /primitives/list.json"


def get_property(primitive: Primitive, name: str, prop: str) -> Any:
    """``primitive``'s (called ``name``) property ``prop`` as JSON."""
    _known(name, prop, primitive.properties, "property")
    return values.jsonable(primitive.get_property(prop))


def set_property(primitive: Primitive, name: str, prop: str, value: Any) -> Any:
    """Set a property (converted and checked by the primitive); its new value as JSON."""
    _known(name, prop, primitive.properties, "property")
    if isinstance(value, float) and not math.isfinite(value):
        raise ApiError("invalid", f"{name}.{prop}: expected a finite number")
    try:
        primitive.set_property(prop, value)  # ArgumentError -> 4xx "invalid"
    except (OverflowError, RecursionError):
        raise ApiError("invalid", f"{name}.{prop}: the value is out of range") from None
    return values.jsonable(primitive.get_property(prop))


def call_method(
    primitive: Primitive,
    name: str,
    method: str,
    args: Sequence[Any] = (),
    kwargs: Mapping[str, Any] | None = None,
) -> Any:
    """Call a declared method; its result as JSON."""
    _known(name, method, primitive.methods, "method")
    try:
        result = getattr(primitive, method)(*args, **(kwargs or {}))
    except (TypeError, ValueError, ArithmeticError) as exc:
        raise ApiError("invalid", f"{name}.{method}: {exc}") from None
    return values.jsonable(result)


def describe(primitive: Primitive, name: str) -> dict[str, Any]:
    """State, properties, methods and error (JSON; the traceback stays in the server's log)."""
    described = values.jsonable(primitive.describe())
    assert isinstance(described, dict)
    if described.get("error"):
        # the traceback (server paths) stays in the server's log, where the primitive put it
        described["error"] = {k: v for k, v in described["error"].items() if k != "traceback"}
    return {"name": name, **described}


def _known(name: str, item: str, known: Any, kind: str) -> None:
    if item not in known:
        listed = ", ".join(known) or "none"
        plural = "properties" if kind == "property" else f"{kind}s"
        message = f"{name} has no {kind} {item!r} ({plural}: {listed})"
        raise ApiError("not_found", message, tip=PRIMITIVE_TIP)
