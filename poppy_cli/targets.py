"""Goto targets typed as ``NAME=DEGREES`` words: one parser for `poppy robot goto` and the TUI."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from poppy_core import checks
from poppy_core.errors import ArgumentError, UnknownMotorError
from poppy_core.trajectory import clamp_goal


class TargetSyntaxError(ArgumentError):
    """A word that is not ``NAME=DEGREES`` with a finite number (a usage error on the command
    line)."""


def parse_targets(
    words: Iterable[str],
    known: Sequence[str],
    limits: Mapping[str, tuple[float, float] | None] | None = None,
) -> dict[str, float]:
    """Parse ``NAME=DEGREES`` words into motor name -> degrees, checking the names against
    ``known``; an angle beyond ``limits`` (motor -> its angle limits in the user frame, None for
    a wheel) is clamped to them, as the library and every server do (``trajectory.clamp_goal``).

    Raises:
        TargetSyntaxError: a word that is not NAME=DEGREES with a finite number, or no word.
        UnknownMotorError: an unknown motor (the known ones are listed).
    """
    targets: dict[str, float] = {}
    for word in words:
        name, sep, text = word.partition("=")
        name = name.strip()
        if not sep or not name:
            raise TargetSyntaxError(f"{word!r} is not NAME=DEGREES (e.g. m1=30)", value=word)
        if name not in known:
            raise UnknownMotorError(
                f"no motor {name!r} (motors: {', '.join(known)})", motor=name, known=list(known)
            )
        try:
            value = float(text)
        except ValueError:
            raise TargetSyntaxError(
                f"{word!r}: {text!r} is not a number of degrees", field=name, value=text
            ) from None
        try:
            checks.number(value, name)
        except ArgumentError:
            raise TargetSyntaxError(
                f"{word!r}: the angle must be a finite number of degrees within "
                f"±{checks.MAX_MAGNITUDE:g}",
                field=name,
                value=value,
            ) from None
        targets[name] = clamp_goal(value, (limits or {}).get(name))
    if not targets:
        raise TargetSyntaxError("no target: type e.g. m1=30 m2=-10")
    return targets
