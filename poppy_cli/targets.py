"""Goto targets typed as ``NAME=DEGREES`` words: one parser for `poppy robot goto` and the TUI."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from poppy_core import checks
from poppy_core.errors import ArgumentError, ConfigError


class TargetSyntaxError(ArgumentError):
    """A word that is not ``NAME=DEGREES`` with a finite number (a usage error on the command
    line)."""


def parse_targets(
    words: Iterable[str],
    known: Sequence[str],
    limits: Mapping[str, tuple[float, float] | None] | None = None,
) -> dict[str, float]:
    """Parse ``NAME=DEGREES`` words into motor name -> degrees, checking the names against
    ``known`` and the angles against ``limits`` (motor -> its angle limits, None for a wheel),
    as the REST API does.

    Raises:
        TargetSyntaxError: a word that is not NAME=DEGREES with a finite number, or no word.
        ConfigError: an unknown motor (the known ones are listed).
        ArgumentError: an angle outside the motor's limits.
    """
    targets: dict[str, float] = {}
    for word in words:
        name, sep, text = word.partition("=")
        name = name.strip()
        if not sep or not name:
            raise TargetSyntaxError(f"{word!r} is not NAME=DEGREES (e.g. m1=30)", value=word)
        if name not in known:
            raise ConfigError(
                f"no motor {name!r} (motors: {', '.join(known)})", field=name, value=name
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
                f"±{checks.MAX_MAGNITUDE:g}", field=name, value=value,
            ) from None  # fmt: skip
        bounds = (limits or {}).get(name)
        if bounds is not None and not bounds[0] <= value <= bounds[1]:
            raise ArgumentError(
                f"{name}: {value:g}° is outside the angle limits [{bounds[0]:g}, {bounds[1]:g}]",
                field=name, value=value, motor=name,
            )  # fmt: skip
        targets[name] = value
    if not targets:
        raise TargetSyntaxError("no target: type e.g. m1=30 m2=-10")
    return targets
