"""The known servo models and lookups by model number or name; standard baud rates."""

from __future__ import annotations

import re

from poppy_core.errors import ProtocolError, UnknownModelError
from poppy_core.models.ax import AX_12A, AX_18A
from poppy_core.models.model import ServoModel
from poppy_core.models.mx import MX_12W, MX_28, MX_64, MX_106
from poppy_core.models.xl320 import XL_320
from poppy_core.models.xseries import XL330_M288, XL430_W250, XM430_W350

ALL_MODELS: tuple[ServoModel, ...] = (
    AX_12A,
    AX_18A,
    MX_12W,
    MX_28,
    MX_64,
    MX_106,
    XL_320,
    XL430_W250,
    XM430_W350,
    XL330_M288,
)

# The standard baud rates of each protocol, as the nominal ints pyserial accepts. Protocol-1
# servos really run at 2 Mbps / (code + 1) (e.g. 57,142 bps for code 34); the nominal rate is within
# the UART's 3 % tolerance and every protocol-1 model's ``baudrate_code`` maps it back.
STANDARD_BAUDRATES: dict[int, tuple[int, ...]] = {
    1: (1_000_000, 500_000, 400_000, 250_000, 200_000, 115_200, 57_600, 19_200, 9_600),
    2: (9_600, 57_600, 115_200, 1_000_000, 2_000_000, 3_000_000, 4_000_000, 4_500_000),
}

_BY_NUMBER: dict[int, ServoModel] = {
    number: model for model in ALL_MODELS for number in model.model_numbers
}

# Trailing letters that name a variant with the same control table (AX-12+/AX-18F, MX-28AT/AR,
# MX-106T/R, XL430-W250-T, XM430-W350-R): stripped when the full name is unknown.
_VARIANT_SUFFIX = re.compile(r"(A?[TR]|\+|F)$")


def _normalise(name: str) -> str:
    return re.sub(r"[\s_\-.]", "", name).upper()


_BY_NAME: dict[str, ServoModel] = {}
for _model in ALL_MODELS:
    _key = _normalise(_model.name)
    _BY_NAME[_key] = _model
    # "AX-12A" is also known as "AX-12"; "MX-12W" as "MX-12".
    if _key[-1] in "AW" and _key[-2].isdigit():
        _BY_NAME[_key[:-1]] = _model


def model_by_number(number: int) -> ServoModel | None:
    """Return the model with this model number (control table address 0), or None if unknown."""
    return _BY_NUMBER.get(number)


def model_by_name(name: str) -> ServoModel:
    """Return a model from its name, case-insensitive, ignoring dashes and spaces.

    Accepts variants such as "AX-12", "ax12a", "AX-12+", "XL320", "MX-28AT", "MX-106R",
    "XL430-W250-T".

    Raises:
        UnknownModelError: no known model matches.
    """
    key = _normalise(name)
    if key in _BY_NAME:
        return _BY_NAME[key]
    stripped = _VARIANT_SUFFIX.sub("", key)
    if stripped != key and stripped in _BY_NAME:
        return _BY_NAME[stripped]
    known = ", ".join(model.name for model in ALL_MODELS)
    raise UnknownModelError(f"unknown servo model {name!r} (known: {known})")


def standard_baudrates(protocol: int) -> tuple[int, ...]:
    """Return the standard (nominal) baud rates of a protocol (see ``STANDARD_BAUDRATES``).

    Raises:
        ProtocolError: the protocol is neither 1 nor 2.
    """
    try:
        return STANDARD_BAUDRATES[protocol]
    except KeyError:
        raise ProtocolError(f"unknown protocol {protocol!r} (expected 1 or 2)") from None
